// Poses between and a little beyond the stamped poses of a trajectory.

#include <gtest/gtest.h>

#include <cmath>

#include "featsense/slam/trajectory/pose_interpolation.hpp"

namespace featsense::slam {
namespace {

Eigen::Isometry3d pose(double x, double yaw) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(x, 2.0 * x, 0.5);
  return p;
}

double yaw_of(const Eigen::Isometry3d& p) { return std::atan2(p.linear()(1, 0), p.linear()(0, 0)); }

Trajectory turning_path() {
  // 1 m/s along (1, 2, 0)/|..| scaled, yawing 0.3 rad/s, a pose every 100 ms.
  Trajectory t;
  for (int i = 0; i <= 10; ++i)
    t.push_back(1'000'000'000LL + i * 100'000'000LL, pose(0.1 * i, 0.03 * i));
  return t;
}

TEST(PoseInterpolation, BetweenPosesTheMotionIsLinearInPositionAndAngle) {
  const PoseInterpolator interpolator(turning_path());
  for (int64_t offset_ms : {0, 35, 100, 449, 999, 1000}) {
    const auto p = interpolator.at(1'000'000'000LL + offset_ms * 1'000'000LL);
    ASSERT_TRUE(p.has_value()) << offset_ms;
    const double s = offset_ms / 1000.0;
    EXPECT_NEAR(p->translation().x(), s, 1e-9);
    EXPECT_NEAR(p->translation().y(), 2.0 * s, 1e-9);
    EXPECT_NEAR(yaw_of(*p), 0.3 * s, 1e-9) << offset_ms;
  }
}

TEST(PoseInterpolation, ALittleBeyondTheEndsTheMotionContinues) {
  const PoseInterpolator interpolator(turning_path(), 0.2);
  const auto after = interpolator.at(2'000'000'000LL + 150'000'000LL);
  ASSERT_TRUE(after.has_value());
  EXPECT_NEAR(after->translation().x(), 1.15, 1e-9);
  EXPECT_NEAR(yaw_of(*after), 0.345, 1e-9);
  const auto before = interpolator.at(1'000'000'000LL - 100'000'000LL);
  ASSERT_TRUE(before.has_value());
  EXPECT_NEAR(before->translation().x(), -0.1, 1e-9);
  EXPECT_NEAR(yaw_of(*before), -0.03, 1e-9);
  EXPECT_FALSE(interpolator.at(2'000'000'000LL + 201'000'000LL).has_value());
  EXPECT_FALSE(interpolator.at(0).has_value());
}

TEST(PoseInterpolation, RotationTakesTheShortWayAcrossPi) {
  Trajectory t;
  t.push_back(0, pose(0.0, M_PI - 0.1));
  t.push_back(1'000'000'000LL, pose(1.0, -M_PI + 0.1));
  const auto middle = PoseInterpolator(t).at(500'000'000LL);
  ASSERT_TRUE(middle.has_value());
  EXPECT_NEAR(std::abs(yaw_of(*middle)), M_PI, 1e-9);
}

TEST(PoseInterpolation, EmptyOrUnstampedTrajectoriesAreRefused) {
  EXPECT_THROW(PoseInterpolator(Trajectory{}), TrajectoryError);
  Trajectory kitti = turning_path();
  kitti.has_stamps = false;
  EXPECT_THROW(PoseInterpolator{kitti}, TrajectoryError);
}

}  // namespace
}  // namespace featsense::slam
