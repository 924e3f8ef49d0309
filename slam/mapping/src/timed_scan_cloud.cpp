#include "timed_scan_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>

#include "featsense/slam/refine/voxel_key.hpp"

namespace featsense::mapping {

TimedScanCloud timed_scan_cloud(const slam::Scan& scan, double voxel_m, int neighbours,
                                size_t max_points) {
  if (!(voxel_m > 0.0)) throw std::invalid_argument("timed_scan_cloud: the voxel must be > 0");
  struct Sum {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    double time_s = 0.0;
    int count = 0;
  };
  std::unordered_map<uint64_t, Sum> voxels;
  voxels.reserve(scan.valid_count() / 8 + 1);
  const float inverse_voxel = static_cast<float>(1.0 / voxel_m);
  const bool timed = scan.time_offset_s.size() == scan.size();
  for (size_t i = 0; i < scan.size(); ++i) {
    if (!scan.valid[i] || !scan.xyz[i].allFinite()) continue;
    Sum& sum = voxels[slam::refine::voxel_key_of(scan.xyz[i], inverse_voxel)];
    sum.point += scan.xyz[i].cast<double>();
    if (timed) sum.time_s += scan.time_offset_s[i];
    ++sum.count;
  }
  // In the order of their keys, so that the same scan always gives the same points.
  std::vector<uint64_t> keys;
  keys.reserve(voxels.size());
  for (const auto& entry : voxels) keys.push_back(entry.first);
  std::sort(keys.begin(), keys.end());
  std::vector<Eigen::Vector3f> centroids;
  std::vector<double> times;
  centroids.reserve(keys.size());
  times.reserve(keys.size());
  for (const uint64_t key : keys) {
    const Sum& sum = voxels.at(key);
    centroids.push_back((sum.point / sum.count).cast<float>());
    times.push_back(sum.time_s / sum.count);
  }
  // The neighbourhoods are those of every voxel's centroid: a thinned cloud's nearest points
  // lie several voxels apart and span corners.
  const size_t every = max_points > 0 && centroids.size() > max_points
                           ? (centroids.size() + max_points - 1) / max_points
                           : 1;
  std::vector<uint32_t> kept;
  TimedScanCloud out;
  out.measured = slam::refine::with_covariances(centroids, neighbours, &kept, every);
  out.times_s.reserve(kept.size());
  for (const uint32_t i : kept) out.times_s.push_back(times[i]);
  return out;
}

slam::refine::GaussianCloud deskewed(const TimedScanCloud& cloud, const slam::SweepMotion& sweep) {
  slam::refine::GaussianCloud out = cloud.measured;
  if (!sweep.moving()) return out;
  for (size_t i = 0; i < out.size(); ++i) {
    const Eigen::Isometry3d T_stamp_then = sweep.at(cloud.times_s[i]);
    out.points[i] = T_stamp_then * out.points[i];
    out.covariances[i] =
        T_stamp_then.linear() * out.covariances[i] * T_stamp_then.linear().transpose();
  }
  return out;
}

}  // namespace featsense::mapping
