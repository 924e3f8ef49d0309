// The second pass's placement: each scan at its corrected pose, its columns moved by the
// motion it was first placed with, not by the corrected poses' interpolation.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"
#include "featsense/slam/trajectory/scan_motions.hpp"

namespace featsense::slam {
namespace {

constexpr int64_t kStart = 1'000'000'000;
constexpr int64_t kPeriod = 100'000'000;

/// 1 beam x 5 columns at `stamp_ns`, column c measured 0.02 c s after it.
Scan scan_at(int64_t stamp_ns) {
  Scan scan = Scan::allocate(1, 5);
  scan.stamp_ns = stamp_ns;
  for (int col = 0; col < 5; ++col) {
    const size_t i = scan.index(0, col);
    scan.time_offset_s[i] = 0.02f * static_cast<float>(col);
    scan.valid[i] = 1;
    scan.xyz[i] = Eigen::Vector3f(5.0f, static_cast<float>(col), 0.0f);
  }
  return scan;
}

Eigen::Isometry3d turned(double yaw_rad, const Eigen::Vector3d& at) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = at;
  return T;
}

/// A placement as the odometry makes it: the pose at the stamp, the columns moved from it by
/// a motion over the period (here one that turns 0.02 rad, unlike the stamps' steps).
ScanPlacement placed_with(const Scan& scan, const Eigen::Isometry3d& at_stamp,
                          const Eigen::Isometry3d& motion) {
  ScanPlacement placement;
  placement.stamp_ns = scan.stamp_ns;
  placement.T_map_sensor = at_stamp;
  placement.column_T_map_sensor = column_poses(scan, at_stamp, [&](double t) {
    return std::optional<Eigen::Isometry3d>(at_stamp * motion_fraction(motion, t / 0.1));
  });
  return placement;
}

TEST(ScanMotions, TheReplayKeepsEachScansMotionFromItsCorrectedPose) {
  const Eigen::Isometry3d motion = turned(0.02, {0.5, 0.0, 0.0});
  ScanMotions motions;
  Trajectory corrected;
  // The corrected poses: the first placement's, moved by a correction (a loop's).
  const Eigen::Isometry3d correction = turned(0.01, {0.3, -0.2, 0.05});
  std::vector<ScanPlacement> first;
  for (int k = 0; k < 4; ++k) {
    const Scan scan = scan_at(kStart + k * kPeriod);
    first.push_back(placed_with(scan, turned(0.0, {0.5 * k, 0.0, 0.0}), motion));
    motions.add(scan, first.back());
    corrected.push_back(scan.stamp_ns, correction * first.back().T_map_sensor);
  }
  EXPECT_EQ(motions.size(), 4u);
  const std::unique_ptr<ScanLocator> replay = make_replay_locator(corrected, motions);
  for (int k = 0; k < 4; ++k) {
    std::string why;
    const std::optional<ScanPlacement> again = replay->locate(scan_at(kStart + k * kPeriod), why);
    ASSERT_TRUE(again) << why;
    ASSERT_EQ(again->column_T_map_sensor.size(), 5u);
    for (size_t col = 0; col < 5; ++col) {
      const Eigen::Isometry3d want = correction * first[k].column_T_map_sensor[col];
      EXPECT_LT((again->column_T_map_sensor[col].matrix() - want.matrix()).norm(), 1e-6)
          << k << " " << col;
    }
  }
  // Interpolating the stamps instead would not turn within the sweep at all here.
  const std::unique_ptr<ScanLocator> interpolated = make_given_pose_locator(corrected, true);
  std::string why;
  const std::optional<ScanPlacement> plain = interpolated->locate(scan_at(kStart + kPeriod), why);
  ASSERT_TRUE(plain) << why;
  const Eigen::Isometry3d last = plain->T_map_sensor.inverse() * plain->column_T_map_sensor[4];
  EXPECT_LT(Eigen::AngleAxisd(last.rotation()).angle(), 1e-9);
}

TEST(ScanMotions, ASweepThatTurnsFasterAndFasterIsReplayedAsPlaced) {
  // A gyroscope-bent sweep: yaw 0.5 t + 1.15 t^2 rad (130 deg/s^2) over 1024 columns in 0.1 s,
  // not a constant velocity. The nine knots keep it within 1e-4 rad and 1e-5 m of every
  // column (the turn's shape between knots: alpha h^2 / 8 = 5e-5 rad).
  Scan scan = Scan::allocate(1, 1024);
  scan.stamp_ns = kStart;
  const auto yaw_at = [](double t) { return 0.5 * t + 1.15 * t * t; };
  for (int col = 0; col < 1024; ++col) {
    const size_t i = scan.index(0, col);
    scan.time_offset_s[i] = 0.1f * static_cast<float>(col) / 1024.f;
    scan.valid[i] = 1;
    scan.xyz[i] = Eigen::Vector3f(5.0f, 0.0f, 0.0f);
  }
  ScanPlacement placement;
  placement.stamp_ns = kStart;
  placement.T_map_sensor = turned(0.3, {10.0, 5.0, 1.0});
  placement.column_T_map_sensor = column_poses(scan, placement.T_map_sensor, [&](double t) {
    return std::optional<Eigen::Isometry3d>(placement.T_map_sensor *
                                            turned(yaw_at(t), {4.0 * t, 0.0, 0.0}));
  });
  ScanMotions motions;
  motions.add(scan, placement);
  Trajectory same;
  same.push_back(kStart, placement.T_map_sensor);
  std::string why;
  const std::optional<ScanPlacement> again = make_replay_locator(same, motions)->locate(scan, why);
  ASSERT_TRUE(again) << why;
  double worst_rad = 0.0, worst_m = 0.0;
  for (size_t col = 0; col < 1024; ++col) {
    const Eigen::Isometry3d diff =
        placement.column_T_map_sensor[col].inverse() * again->column_T_map_sensor[col];
    worst_rad = std::max(worst_rad, Eigen::AngleAxisd(diff.rotation()).angle());
    worst_m = std::max(worst_m, diff.translation().norm());
  }
  EXPECT_LT(worst_rad, 1e-4);
  EXPECT_LT(worst_m, 1e-5);
}

TEST(ScanMotions, AScanWithoutAKeptMotionIsInterpolated) {
  Trajectory corrected;
  for (int k = 0; k < 3; ++k)
    corrected.push_back(kStart + k * kPeriod, turned(0.0, {0.5 * k, 0.0, 0.0}));
  const std::unique_ptr<ScanLocator> replay = make_replay_locator(corrected, ScanMotions());
  std::string why;
  const std::optional<ScanPlacement> placed = replay->locate(scan_at(kStart), why);
  ASSERT_TRUE(placed) << why;
  ASSERT_TRUE(placed->deskewed());
  // 5 m/s between the stamps: the last column, 0.08 s in, 0.4 m on.
  EXPECT_NEAR(placed->column_T_map_sensor[4].translation().x(), 0.4, 1e-6);
  // A rigid placement (no column poses) keeps nothing.
  ScanMotions motions;
  ScanPlacement rigid;
  rigid.stamp_ns = kStart;
  motions.add(scan_at(kStart), rigid);
  EXPECT_EQ(motions.size(), 0u);
}

}  // namespace
}  // namespace featsense::slam
