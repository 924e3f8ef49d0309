#pragma once
/// The features of one scan, what the odometry registers: edge points (on lines: corners,
/// poles, silhouettes) and surface points (on planes), in the sensor frame.

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace featsense::slam {

struct FeatureSet {
  uint64_t sequence = 0;                  ///< the scan's index in its recording
  int64_t stamp_ns = 0;                   ///< the scan's stamp
  std::vector<Eigen::Vector3f> edges;     ///< sensor frame, metres
  std::vector<float> edge_time_s;         ///< per edge point, seconds after stamp_ns
  std::vector<Eigen::Vector3f> surfaces;  ///< sensor frame, metres
  std::vector<float> surface_time_s;      ///< per surface point, seconds after stamp_ns
  /// Whether the scan's intensity image confirmed the edges (false: fusion off, or the scan
  /// has no intensity channel).
  bool intensity_confirmed = false;

  size_t size() const { return edges.size() + surfaces.size(); }
};

}  // namespace featsense::slam
