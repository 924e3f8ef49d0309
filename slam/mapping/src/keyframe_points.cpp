#include "keyframe_points.hpp"

#include <array>
#include <cmath>
#include <unordered_set>

#include "surface_cells.hpp"

namespace featsense::mapping {
KeyframePoints::KeyframePoints(const std::vector<slam::loops::MapKeyframe>& keyframes,
                               double voxel_m, double tile_m)
    : tile_m_(tile_m) {
  std::unordered_set<uint64_t> taken;
  for (const slam::loops::MapKeyframe& keyframe : keyframes) {
    const Eigen::Isometry3f T = keyframe.T_map_sensor.cast<float>();
    for (const Eigen::Vector3f& p : keyframe.cloud.points()) {
      const Eigen::Vector3f q = T * p;
      if (!q.allFinite() || !taken.insert(grid_key(grid_index(q.cast<double>(), voxel_m))).second)
        continue;
      std::array<int32_t, 3> tile = grid_index(q.cast<double>(), tile_m_);
      tile[2] = 0;
      tiles_[grid_key(tile)].push_back(q);
      ++size_;
    }
  }
}

std::vector<Eigen::Vector3f> KeyframePoints::near(const Eigen::Vector3d& centre,
                                                  double radius_m) const {
  std::vector<Eigen::Vector3f> out;
  const auto lo = [&](double v) {
    return static_cast<int32_t>(std::floor((v - radius_m) / tile_m_));
  };
  const auto hi = [&](double v) {
    return static_cast<int32_t>(std::floor((v + radius_m) / tile_m_));
  };
  const double radius2 = radius_m * radius_m;
  for (int32_t x = lo(centre.x()); x <= hi(centre.x()); ++x) {
    for (int32_t y = lo(centre.y()); y <= hi(centre.y()); ++y) {
      const auto tile = tiles_.find(grid_key({x, y, 0}));
      if (tile == tiles_.end()) continue;
      for (const Eigen::Vector3f& p : tile->second)
        if ((p.cast<double>() - centre).head<2>().squaredNorm() <= radius2) out.push_back(p);
    }
  }
  return out;
}

size_t KeyframePoints::bytes() const {
  return size_ * sizeof(Eigen::Vector3f) + tiles_.size() * (sizeof(uint64_t) + 64);
}

}  // namespace featsense::mapping
