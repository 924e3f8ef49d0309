// The motion within a sweep: constant velocity from the stamps, bent by the gyroscope, with
// the gyroscope's bias cancelled against the LiDAR's mean rate.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "featsense/slam/trajectory/pose_interpolation.hpp"
#include "featsense/slam/trajectory/sweep_motion.hpp"

namespace featsense::slam {
namespace {

constexpr int64_t kStamp = 5'000'000'000;
constexpr double kPeriod = 0.1;

/// A yaw that speeds up: yaw(t) = w0 t + alpha t^2 / 2 (t from the stamp), a car entering a
/// corner at about 130 deg/s^2.
constexpr double kW0 = 0.8;
constexpr double kAlpha = 2.3;
double yaw_at(double t) { return kW0 * t + 0.5 * kAlpha * t * t; }

/// 100 Hz gyroscope samples over [t0, t1) from the stamp, reading the yaw rate plus `bias`.
std::vector<ImuSample> gyro(double t0, double t1, const Eigen::Vector3d& bias) {
  std::vector<ImuSample> out;
  for (double t = t0; t < t1 - 1e-9; t += 0.01) {
    ImuSample s;
    s.stamp_ns = kStamp + static_cast<int64_t>(std::llround(t * 1e9));
    s.gyro_radps = Eigen::Vector3d(0, 0, kW0 + kAlpha * t) + bias;
    out.push_back(s);
  }
  return out;
}

Eigen::Isometry3d yawed(double yaw, const Eigen::Vector3d& at = Eigen::Vector3d::Zero()) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = at;
  return T;
}

double yaw_of(const Eigen::Isometry3d& T) { return std::atan2(T.linear()(1, 0), T.linear()(0, 0)); }

/// The LiDAR's motion between the stamps: previous stamp's sensor <- this stamp's.
Eigen::Isometry3d lidar_motion() {
  return yawed(yaw_at(0.0) - yaw_at(-kPeriod), Eigen::Vector3d(0.5, 0.0, 0.0));
}

TEST(SweepMotion, WithoutATwistItIsTheConstantVelocity) {
  const Eigen::Isometry3d motion = yawed(0.1, {0.5, 0.1, 0.0});
  const SweepMotion sweep(motion, kPeriod);
  for (const double t : {-0.05, 0.0, 0.03, 0.1, 0.12}) {
    EXPECT_TRUE(sweep.at(t).isApprox(motion_fraction(motion, t / kPeriod), 1e-12)) << t;
  }
  EXPECT_FALSE(SweepMotion().moving());
  EXPECT_TRUE(SweepMotion().at(0.05).isApprox(Eigen::Isometry3d::Identity()));
}

TEST(SweepMotion, TheGyroscopeFollowsATurnThatSpeedsUpAndItsBiasCancels) {
  const Eigen::Vector3d bias(0.004, -0.003, 0.02);  // about 1 deg/s
  const GyroTwist twist =
      GyroTwist::from_samples(gyro(-kPeriod, 0.0, bias), gyro(0.0, kPeriod, bias),
                              kStamp - static_cast<int64_t>(kPeriod * 1e9), kStamp, kStamp);
  ASSERT_FALSE(twist.empty());
  const SweepMotion bent(lidar_motion(), kPeriod, twist);
  const SweepMotion constant(lidar_motion(), kPeriod);
  double worst_bent = 0.0, worst_constant = 0.0;
  // Up to the last sample; beyond it the rate is held (below).
  for (double t = 0.0; t <= 0.09 + 1e-9; t += 0.005) {
    const double truth = yaw_at(t) - yaw_at(0.0);
    worst_bent = std::max(worst_bent, std::abs(yaw_of(bent.at(t)) - truth));
    worst_constant = std::max(worst_constant, std::abs(yaw_of(constant.at(t)) - truth));
    // The bias across the turn does not tilt the sweep either.
    EXPECT_LT(std::abs(bent.at(t).linear()(2, 0)), 1e-6) << t;
    EXPECT_NEAR(bent.at(t).translation().x(), 0.5 * t / kPeriod, 1e-12);
  }
  // At constant velocity the sweep's end lags alpha T^2 = 0.023 rad; the gyroscope's
  // piecewise-linear rate is exact for a rate linear in time.
  EXPECT_GT(worst_constant, 0.015);
  EXPECT_LT(worst_bent, 1e-6);
  // The last 10 ms of the sweep at the last sample's rate: alpha (10 ms)^2 / 2 behind.
  EXPECT_NEAR(yaw_of(bent.at(kPeriod)), yaw_at(kPeriod) - yaw_at(0.0), 2e-4);
}

TEST(SweepMotion, TheFirstSweepTakesTheMeanRateOverThePeriodAfterIt) {
  // The first scan is deskewed with the motion to the second: the period after its stamp.
  const Eigen::Vector3d bias(0.0, 0.0, -0.015);
  const int64_t next = kStamp + static_cast<int64_t>(kPeriod * 1e9);
  const GyroTwist twist = GyroTwist::from_samples(
      gyro(0.0, kPeriod, bias), gyro(kPeriod, 2 * kPeriod, bias), kStamp, next, kStamp);
  ASSERT_FALSE(twist.empty());
  const SweepMotion bent(yawed(yaw_at(kPeriod) - yaw_at(0.0)), kPeriod, twist);
  for (double t = 0.0; t <= kPeriod + 1e-9; t += 0.01) {
    EXPECT_NEAR(yaw_of(bent.at(t)), yaw_at(t) - yaw_at(0.0), 1e-9) << t;
  }
}

TEST(SweepMotion, SamplesThatLeaveAGapGiveNoTwist) {
  const Eigen::Vector3d no_bias = Eigen::Vector3d::Zero();
  const int64_t previous = kStamp - static_cast<int64_t>(kPeriod * 1e9);
  // Nothing before the stamp: the mean rate is unknown.
  EXPECT_TRUE(
      GyroTwist::from_samples({}, gyro(0.0, kPeriod, no_bias), previous, kStamp, kStamp).empty());
  // Nothing in the sweep.
  EXPECT_TRUE(
      GyroTwist::from_samples(gyro(-kPeriod, 0.0, no_bias), {}, previous, kStamp, kStamp).empty());
  // A hole of 60 ms over the stamp.
  EXPECT_TRUE(GyroTwist::from_samples(gyro(-kPeriod, -0.03, no_bias), gyro(0.03, kPeriod, no_bias),
                                      previous, kStamp, kStamp)
                  .empty());
  // Stamps that do not advance.
  EXPECT_TRUE(GyroTwist::from_samples(gyro(-kPeriod, 0.0, no_bias), gyro(0.0, kPeriod, no_bias),
                                      kStamp, kStamp, kStamp)
                  .empty());
}

TEST(SweepMotion, BadSamplesAreSkipped) {
  const Eigen::Vector3d no_bias = Eigen::Vector3d::Zero();
  std::vector<ImuSample> current = gyro(0.0, kPeriod, no_bias);
  current[3].gyro_radps.x() = std::numeric_limits<double>::quiet_NaN();
  ImuSample late = current[5];
  late.gyro_radps = Eigen::Vector3d(100.0, 100.0, 100.0);
  current.insert(current.begin() + 7, late);  // out of time order: dropped
  const GyroTwist twist =
      GyroTwist::from_samples(gyro(-kPeriod, 0.0, no_bias), current,
                              kStamp - static_cast<int64_t>(kPeriod * 1e9), kStamp, kStamp);
  ASSERT_FALSE(twist.empty());
  const SweepMotion bent(lidar_motion(), kPeriod, twist);
  for (double t = 0.0; t <= 0.09 + 1e-9; t += 0.01) {
    EXPECT_TRUE(bent.at(t).matrix().allFinite());
    EXPECT_NEAR(yaw_of(bent.at(t)), yaw_at(t) - yaw_at(0.0), 1e-5) << t;
  }
}

}  // namespace
}  // namespace featsense::slam
