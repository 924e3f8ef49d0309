#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/test_poses.hpp"
#include "featsense/slam/sim/imu_simulator.hpp"
#include "featsense/slam/sim/trajectory.hpp"

namespace featsense::slam {
namespace {

/// A sensor standing still for 10 s, tilted.
std::unique_ptr<PoseCurve> standing(const Eigen::Isometry3d& T) {
  return make_sampled_trajectory({{0.0, T}, {10.0, T}});
}

TEST(ImuSimulator, AtRestReadsGravityUpInTheSensorFrame) {
  const Eigen::Isometry3d T = test::pose(0.3, 0.2, -0.1, {1, 2, 3});
  const std::vector<ImuSample> samples =
      simulate_imu(*standing(T), ImuModel::exact(), 1, 0.0, 1.0, 1000);
  ASSERT_EQ(samples.size(), 100u);  // 100 Hz over [0, 1)
  EXPECT_EQ(samples.front().stamp_ns, 1000);
  EXPECT_EQ(samples[1].stamp_ns, 1000 + 10'000'000);
  const Eigen::Vector3d up = T.rotation().transpose() * Eigen::Vector3d::UnitZ();
  for (const ImuSample& s : samples) {
    EXPECT_LT((s.accel_mps2 - kStandardGravity * up).norm(), 1e-9);
    EXPECT_LT(s.gyro_radps.norm(), 1e-9);
  }
}

TEST(ImuSimulator, OnACircleReadsTheCentripetalAccelerationAndTheTurnRate) {
  // A circle of radius 20 m at 5 m/s: 1.25 m/s^2 towards the centre, 0.25 rad/s of yaw.
  std::vector<Eigen::Vector3d> waypoints;
  for (int i = 0; i <= 72; ++i) {
    const double a = i * M_PI / 36.0;
    waypoints.emplace_back(20.0 * std::cos(a), 20.0 * std::sin(a), 0.0);
  }
  const std::unique_ptr<PoseCurve> path = make_spline_trajectory(waypoints, 5.0);
  const double mid = path->duration_s() / 2.0;
  const std::vector<ImuSample> samples =
      simulate_imu(*path, ImuModel::exact(), 1, mid, mid + 1.0, 0);
  ASSERT_FALSE(samples.empty());
  for (const ImuSample& s : samples) {
    const Eigen::Isometry3d T = path->pose(static_cast<double>(s.stamp_ns) * 1e-9);
    const Eigen::Vector3d inward =
        -Eigen::Vector3d(T.translation().x(), T.translation().y(), 0).normalized();
    const Eigen::Vector3d expected =
        T.rotation().transpose() * (1.25 * inward + kStandardGravity * Eigen::Vector3d::UnitZ());
    EXPECT_LT((s.accel_mps2 - expected).norm(), 0.02);  // the spline is not quite a circle
    EXPECT_NEAR(s.gyro_radps.z(), 0.25, 0.005);
  }
}

TEST(ImuSimulator, ReadingsOfAPathOfSampledPosesIntegrateToItsChangeOfVelocity) {
  // A TUM-like path, a pose every 50 ms: straight along x at 4 m/s, then straight along y. Its
  // velocity changes at once at the samples; the accelerometer, read every 10 ms, must still
  // integrate to that change (a reading that saw each bend from one sample only counted it
  // twice).
  std::vector<StampedPose> poses;
  for (int i = 0; i <= 80; ++i) {
    const double t = 0.05 * i;
    const double d = 4.0 * t;
    StampedPose sample;
    sample.t_s = t;
    const double turn = std::clamp((t - 1.5) / 1.0, 0.0, 1.0) * M_PI / 2.0;
    // Round the corner with ten chords of a 2.5 m arc (yaw from 0 to 90 deg over 1 s).
    const Eigen::Vector3d p =
        t < 1.5   ? Eigen::Vector3d(d, 0.0, 0.0)
        : t < 2.5 ? Eigen::Vector3d(6.0 + 2.5 * std::sin(turn), 2.5 - 2.5 * std::cos(turn), 0.0)
                  : Eigen::Vector3d(8.5, 2.5 + 4.0 * (t - 2.5), 0.0);
    sample.T_map_sensor =
        Eigen::Translation3d(p) * Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ());
    poses.push_back(sample);
  }
  const std::unique_ptr<PoseCurve> path = make_sampled_trajectory(poses);
  const std::vector<ImuSample> samples = simulate_imu(*path, ImuModel::exact(), 1, 0.5, 3.5, 0);
  // Trapezoid over [1, 3]: the world-frame acceleration, gravity removed.
  Eigen::Vector3d change = Eigen::Vector3d::Zero();
  for (size_t i = 1; i < samples.size(); ++i) {
    const double t0 = static_cast<double>(samples[i - 1].stamp_ns) * 1e-9;
    const double t1 = static_cast<double>(samples[i].stamp_ns) * 1e-9;
    if (t0 < 1.0 - 1e-9 || t1 > 3.0 + 1e-9) continue;
    auto world = [&](const ImuSample& s, double t) {
      return (path->pose(t).rotation() * s.accel_mps2 - kStandardGravity * Eigen::Vector3d::UnitZ())
          .eval();
    };
    change += 0.5 * (t1 - t0) * (world(samples[i - 1], t0) + world(samples[i], t1));
  }
  // From 4 m/s along x to the chord speed along y.
  const Eigen::Vector3d before =
      (poses[20].T_map_sensor.translation() - poses[19].T_map_sensor.translation()) / 0.05;
  const Eigen::Vector3d after =
      (poses[61].T_map_sensor.translation() - poses[60].T_map_sensor.translation()) / 0.05;
  EXPECT_LT((change - (after - before)).norm(), 1e-6) << change.transpose();
}

TEST(ImuSimulator, NoiseAndBiasAreThoseOfTheModelAndRepeatable) {
  const Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const ImuModel model;  // the defaults: 0.02 m/s^2 noise, a 0.05 m/s^2 bias
  const std::vector<ImuSample> a = simulate_imu(*standing(T), model, 7, 0.0, 10.0, 0);
  const std::vector<ImuSample> b = simulate_imu(*standing(T), model, 7, 0.0, 10.0, 0);
  const std::vector<ImuSample> other = simulate_imu(*standing(T), model, 8, 0.0, 10.0, 0);
  ASSERT_EQ(a.size(), 1000u);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const ImuSample& s : a) mean += s.accel_mps2;
  mean /= static_cast<double>(a.size());
  double variance = 0.0;
  for (const ImuSample& s : a) variance += (s.accel_mps2 - mean).squaredNorm();
  variance /= 3.0 * static_cast<double>(a.size());
  EXPECT_NEAR(std::sqrt(variance), model.accel_noise_mps2, 0.002);
  const Eigen::Vector3d bias = mean - Eigen::Vector3d(0, 0, kStandardGravity);
  EXPECT_NEAR(bias.norm(), model.accel_bias_mps2, 0.003);  // the mean of 1000 draws
  EXPECT_EQ(a[123].accel_mps2, b[123].accel_mps2);
  EXPECT_NE(a[123].accel_mps2, other[123].accel_mps2);
}

}  // namespace
}  // namespace featsense::slam

namespace featsense::slam {
namespace {

TEST(ImuSimulator, ConsecutiveSweepsShareNoSample) {
  // Frame k's window is [k / 10, k / 10 + 0.1): 0.2 + 0.1 is a rounding error above 0.3, and
  // the sample at 0.3 s belongs to the next frame only.
  const std::unique_ptr<PoseCurve> path = standing(Eigen::Isometry3d::Identity());
  int64_t last_stamp = -1;
  size_t total = 0;
  for (int frame = 0; frame < 20; ++frame) {
    const double start = frame * 0.1;
    const std::vector<ImuSample> samples =
        simulate_imu(*path, ImuModel::exact(), 1, start, start + 0.1, 0);
    EXPECT_EQ(samples.size(), 10u) << frame;
    for (const ImuSample& s : samples) {
      EXPECT_GT(s.stamp_ns, last_stamp) << frame;
      last_stamp = s.stamp_ns;
    }
    total += samples.size();
  }
  EXPECT_EQ(total, 200u);
}

}  // namespace
}  // namespace featsense::slam
