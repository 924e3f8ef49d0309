// The gyroscope's turn over a period, and the prediction it corrects: against the analytic
// rotation of a sensor whose turn rate changes, with the gyroscope's bias cancelled by the
// LiDAR's last motion.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "featsense/slam/trajectory/gyro_rotation.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"

namespace featsense::slam {
namespace {

constexpr int64_t kStamp = 5'000'000'000;
constexpr double kPeriod = 0.1;

/// A yaw whose rate speeds up sharply, a drone whipping round a corner: yaw(t) = w0 t +
/// alpha t^2 / 2 (t from the stamp; 300 deg/s^2).
constexpr double kW0 = 1.5;
constexpr double kAlpha = 5.2;
double yaw_at(double t) { return kW0 * t + 0.5 * kAlpha * t * t; }

int64_t ns(double t) { return kStamp + static_cast<int64_t>(std::llround(t * 1e9)); }

/// Gyroscope samples every `step` seconds over [t0, t1) from the stamp: the yaw rate plus
/// `bias`, and a slow roll so that the rotation is not about one fixed axis only.
std::vector<ImuSample> gyro(double t0, double t1, const Eigen::Vector3d& bias, double step = 0.01) {
  std::vector<ImuSample> out;
  for (double t = t0; t < t1 - 1e-9; t += step) {
    ImuSample s;
    s.stamp_ns = ns(t);
    s.gyro_radps = Eigen::Vector3d(0.0, 0.0, kW0 + kAlpha * t) + bias;
    out.push_back(s);
  }
  return out;
}

Eigen::Matrix3d yawed(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

TEST(GyroRotation, IntegratesAChangingRateExactlyAtItsSamples) {
  // Over [0, 0.1] from two sweeps' samples, the rate linear: the midpoint rule is exact.
  const auto earlier = gyro(-0.1, 0.0, Eigen::Vector3d::Zero());
  const auto later = gyro(0.0, 0.1, Eigen::Vector3d::Zero());
  const auto turn = gyro_rotation(earlier, later, ns(-0.1), ns(0.0));
  ASSERT_TRUE(turn.has_value());
  EXPECT_NEAR(angle_between(*turn, yawed(yaw_at(0.0) - yaw_at(-0.1))), 0.0, 1e-9);
  // A period that does not start or end on a sample: the rate is interpolated there.
  const auto inside = gyro_rotation(earlier, later, ns(-0.055), ns(0.045));
  ASSERT_TRUE(inside.has_value());
  EXPECT_NEAR(angle_between(*inside, yawed(yaw_at(0.045) - yaw_at(-0.055))), 0.0, 1e-9);
}

TEST(GyroRotation, RotationsAboutChangingAxesComposeInTimeOrder) {
  // A quarter turn about x, then a quarter turn about z: the body-frame product, not the sum.
  std::vector<ImuSample> samples;
  for (int k = 0; k <= 200; ++k) {
    ImuSample s;
    s.stamp_ns = ns(k * 0.0005);
    s.gyro_radps =
        k < 100 ? Eigen::Vector3d(M_PI / 2 / 0.05, 0, 0) : Eigen::Vector3d(0, 0, M_PI / 2 / 0.05);
    samples.push_back(s);
  }
  const auto turn = gyro_rotation(samples, {}, ns(0.0), ns(0.1));
  ASSERT_TRUE(turn.has_value());
  const Eigen::Matrix3d expected =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix() *
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // One sample step straddles the switch: its midpoint mixes the two axes.
  EXPECT_LT(angle_between(*turn, expected), 0.02);
}

TEST(GyroRotation, GapsAndBadSamplesLeaveItUnknown) {
  const auto full = gyro(-0.1, 0.15, Eigen::Vector3d::Zero());
  // Not covered: samples end before the period does.
  EXPECT_FALSE(gyro_rotation(gyro(-0.1, 0.0, Eigen::Vector3d::Zero()), {}, ns(0.0), ns(0.1)));
  // A gap longer than half the period inside it.
  std::vector<ImuSample> gap;
  for (const ImuSample& s : full) {
    if (s.stamp_ns < ns(0.01) || s.stamp_ns > ns(0.07)) gap.push_back(s);
  }
  EXPECT_FALSE(gyro_rotation(gap, {}, ns(0.0), ns(0.1)));
  // A period that is not positive.
  EXPECT_FALSE(gyro_rotation(full, {}, ns(0.05), ns(0.05)));
  // NaN samples and samples out of order are skipped, not integrated.
  std::vector<ImuSample> bad = full;
  bad[12].gyro_radps.x() = std::numeric_limits<double>::quiet_NaN();
  bad.insert(bad.begin() + 15, bad[3]);
  const auto turn = gyro_rotation(bad, {}, ns(0.0), ns(0.1));
  ASSERT_TRUE(turn.has_value());
  EXPECT_TRUE(turn->allFinite());
  EXPECT_NEAR(angle_between(*turn, yawed(yaw_at(0.1) - yaw_at(0.0))), 0.0, 1e-6);
}

TEST(GyroCorrectedPrediction, TheGyroscopeTurnsThePredictionAndItsBiasCancels) {
  // The LiDAR measured the last period's motion; the turn then sped up. A constant-velocity
  // prediction lags by alpha T^2 (3 deg); the gyroscope's, biased by 1 deg/s, does not.
  const Eigen::Vector3d bias(0.0, 0.0, 1.0 * M_PI / 180.0);
  const auto samples = gyro(-0.2, 0.1, bias);
  Eigen::Isometry3d last_motion = Eigen::Isometry3d::Identity();
  last_motion.linear() = yawed(yaw_at(-0.1) - yaw_at(-0.2));
  last_motion.translation() = Eigen::Vector3d(0.3, 0.0, 0.0);
  const Eigen::Isometry3d constant_velocity = motion_fraction(last_motion, 1.0);
  const auto before = gyro_rotation(samples, {}, ns(-0.2), ns(-0.1));
  const auto now = gyro_rotation(samples, {}, ns(-0.1), ns(0.0));
  ASSERT_TRUE(before && now);
  const Eigen::Isometry3d predicted =
      gyro_corrected_prediction(constant_velocity, last_motion, *before, *now, 1.0);
  const Eigen::Matrix3d truth = yawed(yaw_at(0.0) - yaw_at(-0.1));
  EXPECT_GT(angle_between(constant_velocity.linear(), truth), 2.9 * M_PI / 180.0);
  EXPECT_LT(angle_between(predicted.linear(), truth), 1e-6);
  // Without the LiDAR's correction the bias would be in it: 0.1 deg.
  EXPECT_GT(angle_between(*now, truth), 0.09 * M_PI / 180.0);
  EXPECT_TRUE(predicted.translation().isApprox(constant_velocity.translation()));
}

TEST(GyroCorrectedPrediction, ABiasScalesWithAShorterPeriod) {
  // A scan that came after half a period: the prediction is half the last motion, the bias
  // correction half the last period's.
  const Eigen::Vector3d bias(0.0, 0.0, 2.0 * M_PI / 180.0);
  const auto samples = gyro(-0.2, 0.1, bias);
  Eigen::Isometry3d last_motion = Eigen::Isometry3d::Identity();
  last_motion.linear() = yawed(yaw_at(-0.1) - yaw_at(-0.2));
  const auto before = gyro_rotation(samples, {}, ns(-0.2), ns(-0.1));
  const auto now = gyro_rotation(samples, {}, ns(-0.1), ns(-0.05));
  ASSERT_TRUE(before && now);
  const Eigen::Isometry3d predicted =
      gyro_corrected_prediction(motion_fraction(last_motion, 0.5), last_motion, *before, *now, 0.5);
  EXPECT_LT(angle_between(predicted.linear(), yawed(yaw_at(-0.05) - yaw_at(-0.1))), 1e-6);
}

}  // namespace
}  // namespace featsense::slam
