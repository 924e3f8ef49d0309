// A scan as TSDF rays: which rays may interpolate vertically. A wall facing the sensor keeps
// interpolation; the ground far away (seen at a grazing angle) and depth edges lose it.

#include <gtest/gtest.h>

#include <cmath>

#include "scan_to_rays.hpp"

namespace featsense::app {
namespace {

/// One column of `rows` beams 0.35 deg apart (row 0 highest, at +2 deg) hitting `surface`.
template <typename Surface>
slam::Scan column_scan(int rows, Surface surface) {
  slam::Scan scan = slam::Scan::allocate(rows, 1);
  for (int row = 0; row < rows; ++row) {
    const double elevation = (2.0 - 0.35 * row) * M_PI / 180.0;
    const Eigen::Vector3d dir(std::cos(elevation), 0.0, std::sin(elevation));
    const double range = surface(dir);
    if (!(range > 0.0)) continue;
    const size_t i = scan.index(row, 0);
    scan.valid[i] = 1;
    scan.range_m[i] = static_cast<float>(range);
    scan.xyz[i] = (range * dir).cast<float>();
  }
  return scan;
}

TEST(ScanToRays, AWallFacingTheSensorInterpolates) {
  const slam::Scan wall = column_scan(16, [](const Eigen::Vector3d& d) { return 10.0 / d.x(); });
  const tsdf::RayBatch rays = scan_to_rays(wall, Eigen::Isometry3d::Identity());
  ASSERT_EQ(rays.interpolate.size(), 16u);
  for (size_t i = 0; i < rays.size(); ++i) EXPECT_TRUE(rays.may_interpolate(i)) << i;
}

TEST(ScanToRays, GroundAtAGrazingAngleDoesNot) {
  // Beams below the horizon hit the ground 1.8 m down: at 5 deg the next beam lands ~1.5 m
  // farther, far more than the 0.35 deg gap explains for a surface facing the sensor.
  const slam::Scan ground =
      column_scan(32, [](const Eigen::Vector3d& d) { return d.z() < -1e-3 ? -1.8 / d.z() : -1.0; });
  const tsdf::RayBatch rays = scan_to_rays(ground, Eigen::Isometry3d::Identity());
  ASSERT_GT(rays.size(), 10u);
  for (size_t i = 0; i < rays.size(); ++i) EXPECT_FALSE(rays.may_interpolate(i)) << i;
}

TEST(ScanToRays, DepthEdgesDoNotInterpolateAcrossTheGap) {
  // A wall at 5 m up to beam 7, then one at 12 m: the two beams at the edge lose it.
  slam::Scan edge = column_scan(16, [](const Eigen::Vector3d& d) { return 5.0 / d.x(); });
  for (int row = 8; row < 16; ++row) {
    const size_t i = edge.index(row, 0);
    edge.xyz[i] *= 12.0f / 5.0f;
    edge.range_m[i] *= 12.0f / 5.0f;
  }
  const tsdf::RayBatch rays = scan_to_rays(edge, Eigen::Isometry3d::Identity());
  for (size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(rays.may_interpolate(i), i != 7 && i != 8) << i;
  }
}

}  // namespace
}  // namespace featsense::app
