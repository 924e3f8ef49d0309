#pragma once
/// Reading and writing the .h5 map file (layout in FORMAT.md). HDF5 handles appear here as
/// int64_t (hid_t) so that only hdf5_map_file.cpp includes HDF5's headers.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "featsense/storage/chunk.hpp"
#include "featsense/storage/chunk_store.hpp"
#include "featsense/storage/map_sessions.hpp"

namespace featsense::storage::detail {

/// An existing map file, open read-only.
class Hdf5MapReader {
 public:
  /// Throws std::runtime_error (with the path) for a missing, truncated, foreign or damaged
  /// file.
  explicit Hdf5MapReader(const std::filesystem::path& path);
  ~Hdf5MapReader();
  Hdf5MapReader(const Hdf5MapReader&) = delete;
  Hdf5MapReader& operator=(const Hdf5MapReader&) = delete;

  const MapMetadata& metadata() const { return metadata_; }
  const std::vector<ChunkKey>& keys() const { return keys_; }
  /// Throws when the dataset is missing or not uint32 [64][64][64].
  Chunk read(const ChunkKey& key) const;
  std::vector<TrajectoryPose> read_trajectory() const;
  /// Every keyframe in /keyframes, sorted; none when the group is absent (older files).
  std::vector<KeyframeKey> keyframe_keys() const;
  /// Throws when a dataset is missing, of the wrong type or shape, or the pose is not finite.
  StoredKeyframe read_keyframe(const KeyframeKey& key) const;
  /// Sorted by id; none when /sessions is absent (older files).
  std::vector<MapSession> read_sessions() const;
  int64_t handle() const { return file_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  int64_t file_ = -1;
  MapMetadata metadata_;
  std::vector<ChunkKey> keys_;
};

/// A new map file; close() completes it and makes it durable (fsync).
class Hdf5MapWriter {
 public:
  Hdf5MapWriter(const std::filesystem::path& path, const MapMetadata& metadata, int deflate_level);
  ~Hdf5MapWriter();
  Hdf5MapWriter(const Hdf5MapWriter&) = delete;
  Hdf5MapWriter& operator=(const Hdf5MapWriter&) = delete;

  void write_chunk(const ChunkKey& key, const Chunk& chunk);
  /// Copies a chunk dataset as stored (still compressed) from another map file.
  void copy_chunk(const Hdf5MapReader& source, const ChunkKey& key);
  void write_trajectory(const std::vector<TrajectoryPose>& poses);
  void write_keyframe(const StoredKeyframe& keyframe);
  /// Copies a keyframe's group as stored (the cloud still compressed) from another map file.
  void copy_keyframe(const Hdf5MapReader& source, const KeyframeKey& key);
  void write_sessions(const std::vector<MapSession>& sessions);
  void close();

 private:
  std::filesystem::path path_;
  int64_t file_ = -1;
  int64_t chunks_ = -1;
  int64_t dcpl_ = -1;
  int deflate_level_ = 1;
};

/// "x_y_z", the dataset name of a chunk.
std::string chunk_name(const ChunkKey& key);
std::optional<ChunkKey> parse_chunk_name(const std::string& name);

}  // namespace featsense::storage::detail
