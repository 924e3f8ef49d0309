#pragma once
/// A keyframe of a saved map, as relocalization and the links between sessions use it: the
/// session it came from, where it lies in the map, its place descriptor and its points.

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "featsense/slam/loops/compact_cloud.hpp"
#include "featsense/slam/loops/scan_context.hpp"
#include "featsense/slam/refine/gaussian_cloud.hpp"

namespace featsense::slam::loops {

struct MapKeyframe {
  uint32_t session = 0;
  uint32_t index = 0;  ///< within its session
  int64_t stamp_ns = 0;
  Eigen::Isometry3d T_map_sensor = Eigen::Isometry3d::Identity();
  /// How far along its session's path, metres (from the keyframes' positions where the path
  /// is not known).
  double travelled_m = 0.0;
  ScanContext descriptor;
  CompactCloud cloud;
};

/// The travelled_m of each keyframe of `keyframes` (sorted by session, then index) from the
/// distances between consecutive keyframes of the same session.
void travelled_from_positions(std::vector<MapKeyframe>& keyframes);

/// The points of keyframe `centre` and of up to `each_side` keyframes of the same session on
/// either side (neighbours in `poses`' order), in `centre`'s sensor frame, with covariances from
/// `neighbours` nearest: the target a scan is registered to when it revisits `centre`.
/// `poses` are the keyframes' current poses (same order as `keyframes`).
refine::GaussianCloud keyframe_target(const std::vector<MapKeyframe>& keyframes,
                                      const std::vector<Eigen::Isometry3d>& poses, size_t centre,
                                      size_t each_side, int neighbours);

}  // namespace featsense::slam::loops
