#pragma once
// One pass of the mapping pipeline over a recording into a map store: the store opened (new,
// replaced, or a copy of a map being continued), the TSDF backend made when the first scan
// arrives, the pipeline run, the map flushed and the poses written into the store, also when
// the pipeline fails. `featsense map` makes a second pass with the poses the loop closure
// corrected.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/scan_locator.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/storage/shifting_map.hpp"
#include "map_pipeline.hpp"
#include "map_sessions.hpp"

namespace featsense::app {

/// Where a pass writes: OUT/map.h5 new (or replaced with `overwrite`), or continuing a map.
struct MapStoreRequest {
  std::filesystem::path path;
  std::string sensor_name;
  std::optional<std::string> continue_from;
  bool overwrite = false;
  /// The run as the map's new session (map_sessions.hpp).
  SessionDescription session;
  /// The keyframes the session keeps; null: those of this pass's loop closure, where it ran.
  const std::vector<slam::loops::KeyframeRecord>* keyframes = nullptr;
};

struct MapPassOutput {
  PipelineResult result;
  std::string backend = "none";  ///< "cuda" or "cpu" once a scan was integrated
  std::string backend_reason;
  storage::ShiftingMapStats map;
  size_t map_chunks = 0;
  size_t continued_chunks = 0;
  size_t device_memory_bytes = 0;
  std::vector<double> final_flush_ms;
};

/// Runs the pipeline over `source` with `locator` into the store of `request` (none when
/// pipeline.integrate is false). `config` takes a continued map's voxel size and tau. On a
/// failure what was integrated is flushed and the error rethrown.
MapPassOutput run_map_pass(slam::ScanSource& source, slam::ScanLocator& locator,
                           const PipelineSettings& pipeline, config::Config& config,
                           const MapStoreRequest& request);

}  // namespace featsense::app
