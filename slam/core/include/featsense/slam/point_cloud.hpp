#pragma once
/// Unorganized points as many formats store them, before organize() turns them into a Scan.

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "featsense/slam/scan.hpp"

namespace featsense::slam {

struct PointCloud {
  std::vector<Eigen::Vector3f> xyz;  ///< sensor frame, metres
  std::vector<int> ring;             ///< beam index per point, if the format has one
  bool ring_counts_up = true;        ///< Velodyne: ring 0 is the lowest beam; Ouster: highest
  std::vector<float> time_offset_s;  ///< per point after stamp_ns, if the format has one
  /// Per point, metres, where the format stores the sensor's own range; else empty and
  /// organize() uses |xyz|.
  std::vector<float> range_m;
  std::vector<ScanChannel> channels;  ///< per point, same names as in Scan
  int64_t stamp_ns = 0;

  size_t size() const { return xyz.size(); }
};

}  // namespace featsense::slam
