// The front end's stage with given poses: a TUM trajectory interpolated to the scan's stamp
// and to each column's time, KITTI poses by index, and scans the trajectory does not cover.

#include <gtest/gtest.h>

#include <cmath>

#include "featsense/slam/trajectory/given_pose_locator.hpp"

namespace featsense::slam {
namespace {

constexpr int64_t kStart = 1'000'000'000;

/// The sensor moving along x at 2 m/s for 1 s, a pose every 0.1 s.
Trajectory moving_along_x() {
  Trajectory trajectory;
  for (int i = 0; i <= 10; ++i) {
    trajectory.push_back(kStart + i * 100'000'000,
                         Eigen::Isometry3d(Eigen::Translation3d(0.2 * i, 0.0, 0.0)));
  }
  return trajectory;
}

/// 2 beams x 5 columns at `stamp_ns`, column c fired 0.02 c s after it; column 2 is empty.
Scan scan_at(int64_t stamp_ns, uint64_t sequence) {
  Scan scan = Scan::allocate(2, 5);
  scan.stamp_ns = stamp_ns;
  scan.sequence = sequence;
  for (int row = 0; row < 2; ++row) {
    for (int col = 0; col < 5; ++col) {
      const size_t i = scan.index(row, col);
      scan.time_offset_s[i] = 0.02f * static_cast<float>(col);
      if (col == 2) continue;
      scan.valid[i] = 1;
      scan.xyz[i] = Eigen::Vector3f(3.0f, static_cast<float>(col), 0.0f);
    }
  }
  return scan;
}

TEST(GivenPoseLocator, StampedPosesAreInterpolatedToTheStampAndEachColumn) {
  const auto locator = make_given_pose_locator(moving_along_x(), /*deskew=*/true);
  std::string why;
  const std::optional<ScanPlacement> placed =
      locator->locate(scan_at(kStart + 250'000'000, 7), why);
  ASSERT_TRUE(placed) << why;
  EXPECT_EQ(placed->sequence, 7u);
  EXPECT_NEAR(placed->T_map_sensor.translation().x(), 0.5, 1e-12);
  ASSERT_TRUE(placed->deskewed());
  ASSERT_EQ(placed->column_T_map_sensor.size(), 5u);
  for (int col = 0; col < 5; ++col) {
    // 2 m/s x 0.02 s per column; the empty column keeps the scan's pose.
    const double expected = col == 2 ? 0.5 : 0.5 + 0.04 * col;
    EXPECT_NEAR(placed->column_T_map_sensor[static_cast<size_t>(col)].translation().x(), expected,
                1e-6)
        << col;
  }
  EXPECT_TRUE(placed->diagnostics.converged);
  EXPECT_FALSE(placed->diagnostics.degenerate);
}

TEST(GivenPoseLocator, WithoutDeskewingTheScanIsRigid) {
  const auto locator = make_given_pose_locator(moving_along_x(), /*deskew=*/false);
  std::string why;
  const auto placed = locator->locate(scan_at(kStart + 300'000'000, 0), why);
  ASSERT_TRUE(placed) << why;
  EXPECT_FALSE(placed->deskewed());
  EXPECT_NEAR(placed->T_map_sensor.translation().x(), 0.6, 1e-12);
}

TEST(GivenPoseLocator, AScanOutsideTheTrajectoryIsNotPlacedAndSaysWhy) {
  const auto locator = make_given_pose_locator(moving_along_x(), /*deskew=*/true);
  std::string why;
  EXPECT_FALSE(locator->locate(scan_at(kStart + 2'000'000'000, 3), why));
  EXPECT_NE(why.find("scan 3"), std::string::npos) << why;
  EXPECT_NE(why.find("covers"), std::string::npos) << why;
}

TEST(GivenPoseLocator, PosesWithoutStampsBelongToScansByIndex) {
  Trajectory kitti = moving_along_x();
  kitti.has_stamps = false;
  const auto locator = make_given_pose_locator(kitti, /*deskew=*/true);
  std::string why;
  const auto placed = locator->locate(scan_at(123, 4), why);
  ASSERT_TRUE(placed) << why;
  EXPECT_FALSE(placed->deskewed());
  EXPECT_NEAR(placed->T_map_sensor.translation().x(), 0.8, 1e-12);
  EXPECT_FALSE(locator->locate(scan_at(123, 11), why));
  EXPECT_NE(why.find("11 poses"), std::string::npos) << why;
}

}  // namespace
}  // namespace featsense::slam
