#include "featsense/slam/odometry/voxel_filter.hpp"

#include <cmath>
#include <unordered_set>

namespace featsense::slam::odometry {

uint64_t voxel_key(const Eigen::Vector3f& p, float inverse_voxel) {
  uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const auto cell = static_cast<int64_t>(std::floor(p[axis] * inverse_voxel));
    key = (key << 21) | (static_cast<uint64_t>(cell) & ((uint64_t{1} << 21) - 1));
  }
  return key;
}

std::vector<Eigen::Vector3f> voxel_filter(const std::vector<Eigen::Vector3f>& points,
                                          double voxel_m) {
  std::vector<float> kept_times;
  return voxel_filter(points, {}, voxel_m, &kept_times);
}

std::vector<Eigen::Vector3f> voxel_filter(const std::vector<Eigen::Vector3f>& points,
                                          const std::vector<float>& times, double voxel_m,
                                          std::vector<float>* kept_times) {
  const auto inverse = static_cast<float>(1.0 / voxel_m);
  const bool timed = times.size() == points.size();
  std::unordered_set<uint64_t> taken;
  taken.reserve(points.size());
  std::vector<Eigen::Vector3f> kept;
  kept.reserve(points.size());
  kept_times->clear();
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;
    if (!taken.insert(voxel_key(p, inverse)).second) continue;
    kept.push_back(p);
    kept_times->push_back(timed ? times[i] : 0.0f);
  }
  return kept;
}

}  // namespace featsense::slam::odometry
