#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/test_poses.hpp"
#include "featsense/slam/loops/gravity_reference.hpp"
#include "featsense/slam/sim/imu_simulator.hpp"
#include "featsense/slam/sim/trajectory.hpp"

namespace featsense::slam::loops {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// A drive through an S-bend that climbs, speeding up and turning: accelerations of about
/// 1 m/s^2 that an accelerometer mistakes for a tilt of several degrees.
struct Drive {
  std::unique_ptr<PoseCurve> curve;
  std::vector<int64_t> stamps_ns;  ///< a scan every 0.1 s
  std::vector<Eigen::Isometry3d> poses;
  std::vector<ImuSample> imu;

  explicit Drive(const ImuModel& model) {
    curve = make_spline_trajectory(
        {{0, 0, 0}, {20, 2, 0.5}, {40, 15, 1.5}, {45, 35, 2.0}, {70, 45, 2.5}, {90, 40, 3.0}}, 6.0,
        true);
    for (double t = 0.0; t <= curve->duration_s(); t += 0.1) {
      stamps_ns.push_back(static_cast<int64_t>(std::llround(t * 1e9)));
      poses.push_back(curve->pose(t));
    }
    imu = simulate_imu(*curve, model, 3, 0.0, curve->duration_s(), 0);
  }

  /// The keyframes: every tenth scan.
  std::vector<int64_t> keyframes() const {
    std::vector<int64_t> out;
    for (size_t i = 0; i < stamps_ns.size(); i += 10) out.push_back(stamps_ns[i]);
    return out;
  }
};

/// The angle between a keyframe's observed up, put in the map by `T`, and +Z, degrees.
double tilt_deg(const GravityObservation& o, const Eigen::Isometry3d& T,
                const Eigen::Vector3d& bias = Eigen::Vector3d::Zero()) {
  const Eigen::Vector3d up = T.rotation() * o.up(bias).normalized();
  return std::acos(std::clamp(up.z(), -1.0, 1.0)) / kDeg;
}

TEST(GravityReference, TheAccelerationTheOdometryMeasuredLeavesTheUpDirection) {
  const Drive drive(ImuModel::exact());
  const std::vector<int64_t> keyframes = drive.keyframes();
  const std::vector<GravityObservation> observations =
      gravity_observations(drive.stamps_ns, drive.poses, drive.imu, keyframes, {});
  ASSERT_EQ(observations.size(), keyframes.size());
  double worst = 0.0, worst_raw = 0.0;
  for (const GravityObservation& o : observations) {
    const Eigen::Isometry3d T = drive.poses[o.node * 10];
    worst = std::max(worst, tilt_deg(o, T));
    // Without the velocity change, the acceleration reads as a tilt.
    GravityObservation raw = o;
    raw.path_acceleration.setZero();
    worst_raw = std::max(worst_raw, tilt_deg(raw, T));
    EXPECT_GT(o.sigma_rad, 0.0);
  }
  EXPECT_LT(worst, 0.01);
  EXPECT_GT(worst_raw, 0.5);
}

/// A car at 4 m/s that turns into a 3 m bend at once and out of it again (the lateral
/// acceleration steps from 0 to 5.3 m/s^2 and back), sampled every millisecond. It enters the
/// bend at 3.1 s, in the middle of a velocity baseline (the keyframes' windows start at even
/// tenths), where a mean velocity is furthest from the velocity at its middle.
std::unique_ptr<PoseCurve> sharp_bend() {
  std::vector<StampedPose> poses;
  const double speed = 4.0, radius = 3.0, straight = 12.4;
  const double arc = radius * M_PI / 2.0;
  for (double t = 0.0; t <= (2.0 * straight + arc) / speed + 1e-9; t += 0.001) {
    const double d = speed * t;
    Eigen::Vector3d p;
    double yaw = 0.0;
    if (d < straight) {
      p = {d, 0.0, 0.0};
    } else if (d < straight + arc) {
      yaw = (d - straight) / radius;
      p = {straight + radius * std::sin(yaw), radius - radius * std::cos(yaw), 0.0};
    } else {
      yaw = M_PI / 2.0;
      p = {straight + radius, radius + d - straight - arc, 0.0};
    }
    StampedPose sample;
    sample.t_s = t;
    sample.T_map_sensor =
        Eigen::Translation3d(p) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
    poses.push_back(sample);
  }
  return make_sampled_trajectory(poses);
}

TEST(GravityReference, ABendEnteredAtOnceLeavesNoTilt) {
  // A mean velocity over the baseline is not the velocity at its middle where the
  // acceleration steps (a / 8 x baseline off, 0.13 m/s here, a tilt of 0.24 deg over the 4 s
  // window): the accelerometer must be averaged with the weights that two such means give it.
  const std::unique_ptr<PoseCurve> curve = sharp_bend();
  std::vector<int64_t> stamps_ns;
  std::vector<Eigen::Isometry3d> poses;
  for (double t = 0.0; t <= curve->duration_s(); t += 0.1) {
    stamps_ns.push_back(static_cast<int64_t>(std::llround(t * 1e9)));
    poses.push_back(curve->pose(t));
  }
  const std::vector<ImuSample> imu =
      simulate_imu(*curve, ImuModel::exact(), 3, 0.0, curve->duration_s(), 0);
  std::vector<int64_t> keyframes;
  for (size_t i = 0; i < stamps_ns.size(); i += 2) keyframes.push_back(stamps_ns[i]);
  const std::vector<GravityObservation> observations =
      gravity_observations(stamps_ns, poses, imu, keyframes, {});
  ASSERT_GT(observations.size(), keyframes.size() / 2);
  double worst = 0.0;
  for (const GravityObservation& o : observations) {
    worst = std::max(worst, tilt_deg(o, poses[o.node * 2]));
  }
  RecordProperty("worst_tilt_deg", std::to_string(worst));
  EXPECT_LT(worst, 0.02);
}

TEST(GravityReference, TheOdometrysJitterAveragesOverTheWindow) {
  // Each scan's position off by up to 1 cm (uniform, 5.8 mm standard deviation), as an
  // odometry's registrations scatter from scan to scan: the acceleration rests on every
  // position in the window, not on the four at its ends (two mean velocities over 0.2 s read
  // such jitter as a tilt of 0.1 - 0.2 deg).
  const Drive drive(ImuModel::exact());
  std::vector<Eigen::Isometry3d> jittered = drive.poses;
  uint64_t state = 12345;
  const auto uniform = [&state]() {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / static_cast<double>(1ULL << 53) * 2.0 - 1.0;
  };
  for (Eigen::Isometry3d& T : jittered)
    T.translation() += 0.01 * Eigen::Vector3d(uniform(), uniform(), uniform());
  const std::vector<GravityObservation> observations =
      gravity_observations(drive.stamps_ns, jittered, drive.imu, drive.keyframes(), {});
  ASSERT_EQ(observations.size(), drive.keyframes().size());
  double worst = 0.0;
  for (const GravityObservation& o : observations) {
    const double tilt = tilt_deg(o, drive.poses[o.node * 10]);
    worst = std::max(worst, tilt);
    // The claimed sigma covers the error.
    EXPECT_LT(tilt * kDeg, 3.0 * o.sigma_rad);
  }
  RecordProperty("worst_tilt_deg", std::to_string(worst));
  EXPECT_LT(worst, 0.04);
}

TEST(GravityReference, AWindowThatAcceleratesIsAsUncertainAsTheOdometrysAcceleration) {
  // The odometry's acceleration errs alike in every bend: a window's error grows with the
  // acceleration it takes from the odometry, 3 % of it by default.
  const Drive drive(ImuModel::exact());
  GravitySettings exact_odometry;
  exact_odometry.odometry_acceleration_error = 0.0;
  const std::vector<GravityObservation> with_error =
      gravity_observations(drive.stamps_ns, drive.poses, drive.imu, drive.keyframes(), {});
  const std::vector<GravityObservation> without = gravity_observations(
      drive.stamps_ns, drive.poses, drive.imu, drive.keyframes(), exact_odometry);
  ASSERT_EQ(with_error.size(), without.size());
  double largest = 0.0;
  for (size_t i = 0; i < with_error.size(); ++i) {
    const double a = with_error[i].path_acceleration.norm();
    largest = std::max(largest, a);
    const double odometry_rad = 0.03 * a / std::max(with_error[i].up().norm(), 1.0);
    EXPECT_NEAR(with_error[i].sigma_rad * with_error[i].sigma_rad -
                    without[i].sigma_rad * without[i].sigma_rad,
                odometry_rad * odometry_rad * with_error[i].shared, 1e-12);
  }
  EXPECT_GT(largest, 0.3);  // the drive does accelerate
}

TEST(GravityReference, ATiltedMapFrameShowsAsTheSameTiltOfEveryKeyframe) {
  // The odometry's whole path tilted by 2 degrees (the first scan's tilt kept as the map's):
  // the observations, made of relative rotations only, are the same; put in the tilted map
  // they all lean by the tilt.
  const Drive drive(ImuModel::exact());
  const Eigen::Isometry3d tilt = test::pose(0.0, 2.0 * kDeg, 0.0, Eigen::Vector3d::Zero());
  std::vector<Eigen::Isometry3d> tilted;
  for (const Eigen::Isometry3d& T : drive.poses) tilted.push_back(tilt * T);
  const std::vector<GravityObservation> observations =
      gravity_observations(drive.stamps_ns, tilted, drive.imu, drive.keyframes(), {});
  ASSERT_FALSE(observations.empty());
  for (const GravityObservation& o : observations)
    EXPECT_NEAR(tilt_deg(o, tilted[o.node * 10]), 2.0, 0.02);
}

TEST(GravityReference, TheBiasEntersThroughTheRotations) {
  ImuModel model = ImuModel::exact();
  model.accel_bias_mps2 = 0.3;
  const Drive biased(model);
  const std::vector<GravityObservation> observations =
      gravity_observations(biased.stamps_ns, biased.poses, biased.imu, biased.keyframes(), {});
  ASSERT_FALSE(observations.empty());
  // The bias the simulator drew, recovered at rest from the first sample's error.
  const Drive exact(ImuModel::exact());
  const Eigen::Vector3d bias = biased.imu[0].accel_mps2 - exact.imu[0].accel_mps2;
  EXPECT_NEAR(bias.norm(), 0.3, 1e-9);
  for (const GravityObservation& o : observations)
    EXPECT_LT(tilt_deg(o, biased.poses[o.node * 10], bias), 0.02);
}

TEST(GravityReference, NoSamplesOrTooFewGiveNoObservation) {
  const Drive drive(ImuModel::exact());
  EXPECT_TRUE(
      gravity_observations(drive.stamps_ns, drive.poses, {}, drive.keyframes(), {}).empty());
  const std::vector<ImuSample> few(drive.imu.begin(), drive.imu.begin() + 5);
  EXPECT_TRUE(
      gravity_observations(drive.stamps_ns, drive.poses, few, drive.keyframes(), {}).empty());
  GravitySettings off;
  off.enabled = false;
  EXPECT_TRUE(gravity_observations(drive.stamps_ns, drive.poses, drive.imu, drive.keyframes(), off)
                  .empty());
}

TEST(GravityReference, SamplesOutOfOrderAreDropped) {
  std::vector<ImuSample> log;
  ImuSample a, b, c;
  a.stamp_ns = 10;
  b.stamp_ns = 20;
  c.stamp_ns = 15;
  append_in_time_order(&log, {a, b});
  append_in_time_order(&log, {c, b});
  ASSERT_EQ(log.size(), 2u);
  EXPECT_EQ(log.back().stamp_ns, 20);
}

}  // namespace
}  // namespace featsense::slam::loops
