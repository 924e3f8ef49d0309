#pragma once
/// Keyframes and the sessions table as journal payloads (layout in FORMAT.md), their names in
/// the .h5, and the checks every keyframe and session passes before it is stored.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "featsense/storage/chunk.hpp"
#include "featsense/storage/map_sessions.hpp"

namespace featsense::storage::detail {

/// Throws std::invalid_argument naming the keyframe (and `path`, the map) when its descriptor
/// is not rows x cols, its cloud not whole points, or its stamp or pose not finite.
void check_keyframe(const StoredKeyframe& keyframe, const std::filesystem::path& path);
/// Throws std::invalid_argument when two sessions share an id or a stamp is not finite.
void check_sessions(const std::vector<MapSession>& sessions, const std::filesystem::path& path);

/// A journal record's key carries the keyframe key (x: session, y: index), so that replay
/// finds every keyframe without reading its payload.
ChunkKey record_key_of(const KeyframeKey& key);
KeyframeKey keyframe_key_of_record(const ChunkKey& record_key);

std::vector<uint8_t> encode_keyframe(const StoredKeyframe& keyframe);
/// Throws std::runtime_error naming `source` when the payload is not a whole keyframe.
StoredKeyframe decode_keyframe(const std::vector<uint8_t>& payload,
                               const std::filesystem::path& source);
std::vector<uint8_t> encode_sessions(const std::vector<MapSession>& sessions);
std::vector<MapSession> decode_sessions(const std::vector<uint8_t>& payload,
                                        const std::filesystem::path& source);

/// "s<session>_k<index>", the group of a keyframe in /keyframes.
std::string keyframe_name(const KeyframeKey& key);
std::optional<KeyframeKey> parse_keyframe_name(const std::string& name);
/// "s<id>", the group of a session in /sessions.
std::string session_name(uint32_t id);

}  // namespace featsense::storage::detail
