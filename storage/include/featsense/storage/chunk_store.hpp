#pragma once
/// The interface of the global map store: chunks by key, plus the map's metadata.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "featsense/storage/chunk.hpp"

namespace featsense::storage {

/// The version this program writes. Version 2 added the sessions and keyframes; version 1
/// files are still read (as having none). FORMAT.md, "Compatibility", says why it changed.
constexpr int32_t kFormatVersion = 2;
constexpr int32_t kOldestReadFormatVersion = 1;

/// Written when a map is created, checked when it is opened.
struct MapMetadata {
  int32_t format_version = kFormatVersion;
  double voxel_size_m = 0.0;    ///< edge of a voxel, metres
  double truncation_m = 0.0;    ///< tau, metres: value 32767 means +tau
  int32_t value_scale = 32767;  ///< featsense::tsdf::kValueScale
  int32_t weight_scale = 64;    ///< featsense::tsdf::kWeightScale
  int32_t chunk_size = kChunkSize;
  double max_weight = 0.0;  ///< w_max of the fusion, in measurements
  std::string sensor;       ///< sensor model name
  std::string config_yaml;  ///< the run's configuration (featsense::config::to_yaml)
};

/// One pose of the trajectory: time (seconds) and T_map_sensor as translation (metres) and a
/// unit quaternion.
///
/// Seconds since 1970 in a double keep about 0.24 us: a stamp read back (rounded to whole
/// nanoseconds) lies up to about 300 ns from the one written (twice that after 2106). Code
/// that matches stored stamps to a recording's scans does so within kStoredStampToleranceNs.
struct TrajectoryPose {
  double t_s = 0.0;
  double x = 0.0, y = 0.0, z = 0.0;
  double qx = 0.0, qy = 0.0, qz = 0.0, qw = 1.0;
};

/// How far a stamp read back from TrajectoryPose::t_s may lie from the scan's own stamp: well
/// above the rounding above, far below the time between two scans of any sensor.
constexpr int64_t kStoredStampToleranceNs = 1000;

class ChunkStore {
 public:
  virtual ~ChunkStore() = default;

  /// The chunk at `key`, or nothing when it was never written (or only written empty).
  virtual std::optional<Chunk> read(const ChunkKey& key) = 0;
  /// Stores `chunk` at `key`; an empty chunk (all weights 0) removes the key.
  virtual void write(const ChunkKey& key, const Chunk& chunk) = 0;
  /// Every stored key, sorted.
  virtual std::vector<ChunkKey> keys() const = 0;
  /// Makes every write so far durable: after it returns, a crash loses none of them.
  virtual void flush() = 0;
  virtual const MapMetadata& metadata() const = 0;
};

}  // namespace featsense::storage
