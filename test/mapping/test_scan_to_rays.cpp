// A scan as TSDF rays: which rays may interpolate vertically. A wall facing the sensor keeps
// interpolation; the ground far away (seen at a grazing angle) and depth edges lose it.

#include <gtest/gtest.h>

#include <cmath>

#include "featsense/mapping/scan_to_rays.hpp"

namespace featsense::mapping {
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
  const tsdf::RayBatch rays = scan_to_rays(wall, slam::ScanPlacement{});
  ASSERT_EQ(rays.interpolate.size(), 16u);
  for (size_t i = 0; i < rays.size(); ++i) EXPECT_TRUE(rays.may_interpolate(i)) << i;
}

TEST(ScanToRays, GroundAtAGrazingAngleDoesNot) {
  // Beams below the horizon hit the ground 1.8 m down: at 5 deg the next beam lands ~1.5 m
  // farther, far more than the 0.35 deg gap explains for a surface facing the sensor.
  const slam::Scan ground =
      column_scan(32, [](const Eigen::Vector3d& d) { return d.z() < -1e-3 ? -1.8 / d.z() : -1.0; });
  const tsdf::RayBatch rays = scan_to_rays(ground, slam::ScanPlacement{});
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
  const tsdf::RayBatch rays = scan_to_rays(edge, slam::ScanPlacement{});
  for (size_t i = 0; i < rays.size(); ++i) {
    EXPECT_EQ(rays.may_interpolate(i), i != 7 && i != 8) << i;
  }
}

TEST(ScanToRays, CarvingLevelsFormALatticeOfBeamsAndColumns) {
  // 8 x 8 cells, all valid but (2, 4): each ray's level is the largest L with its beam and
  // its column multiples of 2^L, and both conversions give the same levels to the same cells.
  slam::Scan scan = slam::Scan::allocate(8, 8);
  for (int row = 0; row < 8; ++row) {
    for (int col = 0; col < 8; ++col) {
      if (row == 2 && col == 4) continue;
      const size_t i = scan.index(row, col);
      scan.valid[i] = 1;
      scan.xyz[i] =
          Eigen::Vector3f(5.0f, 0.1f * static_cast<float>(col), 0.1f * static_cast<float>(row));
      scan.range_m[i] = scan.xyz[i].norm();
      scan.time_offset_s[i] = 0.01f * static_cast<float>(col);
    }
  }
  const auto expected = [](int row, int col) -> int {
    if (row == 0 && col == 0) return tsdf::kFullCarvingLevel;
    int level = 0;
    while (row % (2 << level) == 0 && col % (2 << level) == 0) ++level;
    return level;
  };
  const tsdf::RayBatch rays = scan_to_rays(scan, slam::ScanPlacement{});
  ASSERT_EQ(rays.carving_level.size(), 63u);
  slam::ScanPlacement moving;
  moving.column_T_map_sensor.assign(8, Eigen::Isometry3d::Identity());
  const tsdf::RayBatch deskewed = scan_to_rays(scan, moving);
  ASSERT_EQ(deskewed.carving_level.size(), 63u);
  size_t k = 0;
  for (int row = 0; row < 8; ++row) {  // both come row by row
    for (int col = 0; col < 8; ++col) {
      if (row == 2 && col == 4) continue;
      EXPECT_EQ(rays.carving_level[k], expected(row, col)) << row << ", " << col;
      EXPECT_EQ(deskewed.carving_level[k], expected(row, col)) << row << ", " << col;
      ++k;
    }
  }
  EXPECT_EQ(rays.carving_level[0], tsdf::kFullCarvingLevel);
  EXPECT_EQ(rays.carving_level[4 * 8 + 4 - 1], 2) << "(4, 4)";  // one cell before is missing
}

TEST(ScanToRays, DeskewedRaysStartWhereTheSensorWasWhenTheirColumnFired) {
  // 4 beams x 6 columns, the sensor at x = 0.1 c m when column c fired; column 3 has no valid
  // point. Each ray starts at its column's position and its end point moved with it, row by
  // row; the sensor's up axis is the one at the stamp.
  slam::Scan scan = slam::Scan::allocate(4, 6);
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 6; ++col) {
      const size_t i = scan.index(row, col);
      if (col == 3 || (row == 0 && col == 1)) continue;
      scan.valid[i] = 1;
      scan.xyz[i] = Eigen::Vector3f(4.0f, static_cast<float>(col), static_cast<float>(row));
      scan.range_m[i] = scan.xyz[i].norm();
    }
  }
  slam::ScanPlacement placement;
  for (int col = 0; col < 6; ++col) {
    placement.column_T_map_sensor.emplace_back(Eigen::Translation3d(0.1 * col, 0.0, 0.0));
  }
  const tsdf::RayBatch rays = scan_to_rays(scan, placement);
  ASSERT_EQ(rays.size(), 19u);
  ASSERT_EQ(rays.origins_m.size(), 19u);
  size_t k = 0;
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 6; ++col) {
      if (col == 3 || (row == 0 && col == 1)) continue;
      const float x = static_cast<float>(0.1 * col);
      EXPECT_FLOAT_EQ(rays.origins_m[k].x, x) << row << ", " << col;
      EXPECT_FLOAT_EQ(rays.endpoints_m[k].x, 4.0f + x) << row << ", " << col;
      EXPECT_FLOAT_EQ(rays.endpoints_m[k].y, static_cast<float>(col));
      EXPECT_FLOAT_EQ(rays.endpoints_m[k].z, static_cast<float>(row));
      ++k;
    }
  }
}

TEST(ScanToRays, APlacementWithTheWrongNumberOfColumnPosesIsRefused) {
  slam::Scan scan = slam::Scan::allocate(2, 4);
  scan.valid[0] = 1;
  scan.xyz[0] = Eigen::Vector3f(1.0f, 0.0f, 0.0f);
  slam::ScanPlacement placement;
  placement.column_T_map_sensor.assign(3, Eigen::Isometry3d::Identity());
  EXPECT_THROW(scan_to_rays(scan, placement), std::invalid_argument);
}

}  // namespace
}  // namespace featsense::mapping
