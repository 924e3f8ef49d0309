#pragma once
// What a mapping run records of itself in the map file: the run as a session (its input, its scans,
// how its poses were placed) and the keyframes of its loop closure at their final poses, in
// the map frame, so that a later recording can be placed in the map by them
// (storage/FORMAT.md, /sessions and /keyframes).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"

namespace featsense::mapping {

struct SessionDescription {
  std::string input;      ///< the recording, as given
  std::string format;     ///< the reader's format name
  std::string placement;  ///< how its poses were placed in the map
};

/// Adds this run to `store` as a new session, the next id after those the store holds (a
/// continued map keeps its earlier ones), with the stamps of `poses` and its `keyframes`
/// (none where loop closure was off). Returns the session's id.
uint32_t record_session(storage::Hdf5ChunkStore& store, const SessionDescription& session,
                        const slam::Trajectory& poses,
                        const std::vector<slam::loops::KeyframeRecord>& keyframes);

/// The sessions and keyframes of `from` into `to`, one keyframe at a time (a map continued
/// into another file keeps them).
void copy_sessions(const storage::Hdf5ChunkStore& from, storage::Hdf5ChunkStore& to);

}  // namespace featsense::mapping
