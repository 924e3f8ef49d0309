#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstddef>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "featsense/slam/odometry/local_feature_map.hpp"
#include "featsense/slam/odometry/voxel_filter.hpp"

namespace featsense::slam::odometry {
namespace {

/// What the map must hold, kept the plain way: the first point of each voxel, those farther
/// than the radius from the sensor dropped after each scan.
class PlainMap {
 public:
  PlainMap(double voxel_m, float radius)
      : inverse_(static_cast<float>(1.0 / voxel_m)), radius_(radius) {}

  void add(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& T_map_sensor) {
    const Eigen::Isometry3f T = T_map_sensor.cast<float>();
    for (const Eigen::Vector3f& p : points) {
      const Eigen::Vector3f x = T * p;
      kept_.emplace(voxel_key(x, inverse_), x);  // the first one stays
    }
    const Eigen::Vector3f centre = T_map_sensor.translation().cast<float>();
    for (auto it = kept_.begin(); it != kept_.end();)
      it = (it->second - centre).squaredNorm() > radius_ * radius_ ? kept_.erase(it) : ++it;
  }

  /// The k nearest within max_distance, nearest first, by a look at every point.
  std::vector<Eigen::Vector3d> nearest(const Eigen::Vector3d& query, size_t k,
                                       double max_distance) const {
    const Eigen::Vector3f q = query.cast<float>();
    std::vector<std::pair<float, Eigen::Vector3f>> all;
    for (const auto& [key, p] : kept_) all.emplace_back((p - q).squaredNorm(), p);
    const size_t first = std::min(k, all.size());
    std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(first), all.end(),
                      [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<Eigen::Vector3d> out;
    for (size_t i = 0; i < first; ++i) {
      if (all[i].first > max_distance * max_distance) break;
      out.push_back(all[i].second.cast<double>());
    }
    return out;
  }

  size_t size() const { return kept_.size(); }

 private:
  float inverse_;
  float radius_;
  std::map<uint64_t, Eigen::Vector3f> kept_;
};

TEST(LocalFeatureMap, FindsWhatAPlainSearchOfTheKeptPointsFindsAsTheSensorDrivesOn) {
  constexpr double kEdgeVoxel = 0.3, kSurfaceVoxel = 0.2;
  constexpr float kRadius = 15.0f;
  LocalFeatureMap map(kEdgeVoxel, kSurfaceVoxel, kRadius);
  PlainMap edges(kEdgeVoxel, kRadius), surfaces(kSurfaceVoxel, kRadius);
  std::mt19937 random(11);
  std::uniform_real_distribution<float> around(-20.0f, 20.0f);
  std::uniform_real_distribution<double> near(-12.0, 12.0);
  std::vector<Eigen::Vector3d> found;
  // 80 scans, 0.7 m apart and turning: the map's points are dropped and made again many
  // times over (its own storage is compacted on the way).
  for (int scan = 0; scan < 80; ++scan) {
    const Eigen::Isometry3d T = Eigen::Translation3d(0.7 * scan, 0.2 * scan, 0.0) *
                                Eigen::AngleAxisd(0.05 * scan, Eigen::Vector3d::UnitZ());
    std::vector<Eigen::Vector3f> new_edges, new_surfaces;
    for (int i = 0; i < 300; ++i)
      new_edges.emplace_back(around(random), around(random), 0.5f * around(random));
    for (int i = 0; i < 1500; ++i)
      new_surfaces.emplace_back(around(random), around(random), 0.1f * around(random));
    map.add(new_edges, new_surfaces, T);
    edges.add(new_edges, T);
    surfaces.add(new_surfaces, T);
    ASSERT_EQ(map.edge_count(), edges.size()) << "scan " << scan;
    ASSERT_EQ(map.surface_count(), surfaces.size()) << "scan " << scan;
    for (int q = 0; q < 40; ++q) {
      const Eigen::Vector3d query = T * Eigen::Vector3d(near(random), near(random), 0.0);
      map.nearest_surfaces(query, 5, 1.0, found);
      ASSERT_EQ(found, surfaces.nearest(query, 5, 1.0)) << "scan " << scan;
      map.nearest_edges(query, 5, 2.0, found);
      ASSERT_EQ(found, edges.nearest(query, 5, 2.0)) << "scan " << scan;
    }
  }
}

}  // namespace
}  // namespace featsense::slam::odometry
