#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

#include "keyframe_points.hpp"

namespace featsense::mapping {
namespace {

/// A wall along x at y = 30.2 in the map (mid-voxel), 0.1 m apart, as a keyframe at `T_map_sensor`
/// sees it (its points in its own frame).
slam::loops::MapKeyframe seeing_the_wall(const Eigen::Isometry3d& T_map_sensor) {
  std::vector<Eigen::Vector3f> points;
  for (double x = -20.0; x <= 20.0; x += 0.1)
    for (double z = 0.05; z <= 3.0; z += 0.1)
      points.push_back((T_map_sensor.inverse() * Eigen::Vector3d(x, 30.2, z)).cast<float>());
  slam::loops::MapKeyframe keyframe;
  keyframe.T_map_sensor = T_map_sensor;
  keyframe.cloud = slam::loops::CompactCloud(points);
  return keyframe;
}

TEST(KeyframePoints, AWallSeenByTwoKeyframesIsKeptOncePerVoxelInTheMapFrame) {
  const Eigen::Isometry3d first = Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d second =
      Eigen::Translation3d(5.0, -2.0, 0.3) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ());
  const KeyframePoints points({seeing_the_wall(first), seeing_the_wall(second)}, 0.4);
  // 40 m x 3 m of wall at 0.4 m voxels: about 100 x 8 voxels, once each, whichever keyframe.
  EXPECT_GT(points.size(), 700u);
  EXPECT_LT(points.size(), 1000u);
  const std::vector<Eigen::Vector3f> all = points.near(Eigen::Vector3d::Zero(), 100.0);
  EXPECT_EQ(all.size(), points.size());
  for (const Eigen::Vector3f& p : all) EXPECT_NEAR(p.y(), 30.2, 0.02);  // the map's wall
}

TEST(KeyframePoints, NearGivesThePointsWithinTheRadiusHorizontally) {
  const KeyframePoints points({seeing_the_wall(Eigen::Isometry3d::Identity())}, 0.4, 7.0);
  const Eigen::Vector3d centre(10.0, 30.2, -50.0);  // height does not count
  const std::vector<Eigen::Vector3f> near = points.near(centre, 5.0);
  ASSERT_FALSE(near.empty());
  size_t within = 0;
  for (const Eigen::Vector3f& p : points.near(centre, 1000.0))
    if ((p.cast<double>() - centre).head<2>().norm() <= 5.0) ++within;
  EXPECT_EQ(near.size(), within);
  for (const Eigen::Vector3f& p : near)
    EXPECT_LE((p.cast<double>() - centre).head<2>().norm(), 5.0);
  EXPECT_TRUE(points.near(Eigen::Vector3d(0.0, -40.0, 0.0), 5.0).empty());
}

}  // namespace
}  // namespace featsense::mapping
