#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "featsense/slam/loops/gyro_reference.hpp"
#include "featsense/slam/sim/imu_simulator.hpp"
#include "featsense/slam/sim/trajectory.hpp"

namespace featsense::slam::loops {
namespace {

constexpr double kDeg = M_PI / 180.0;

double angle(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

Eigen::Matrix3d exp_map(const Eigen::Vector3d& w) {
  return w.norm() < 1e-15 ? Eigen::Matrix3d::Identity()
                          : Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
}

/// A drone's flight that climbs, turns and banks, a keyframe every 0.6 s, with the IMU of
/// `model` riding along.
struct Flight {
  std::unique_ptr<PoseCurve> curve;
  std::vector<int64_t> keyframes_ns;
  std::vector<Eigen::Matrix3d> rotations;  ///< R_map_sensor at the keyframes
  std::vector<ImuSample> imu;

  explicit Flight(const ImuModel& model) {
    curve = make_spline_trajectory(
        {{0, 0, 1}, {8, 3, 2}, {12, 12, 3}, {4, 18, 2.5}, {-4, 10, 2}, {0, 2, 1.5}}, 3.0, true);
    for (double t = 0.0; t <= curve->duration_s(); t += 0.6) {
      keyframes_ns.push_back(static_cast<int64_t>(std::llround(t * 1e9)));
      rotations.push_back(curve->pose(t).rotation());
    }
    imu = simulate_imu(*curve, model, 5, 0.0, curve->duration_s(), 0);
  }

  Eigen::Matrix3d truth(const GyroObservation& o) const {
    return rotations[o.from].transpose() * rotations[o.to];
  }
};

TEST(GyroReference, TheTurnBetweenKeyframesIsTheSamplesChained) {
  const Flight flight(ImuModel::exact());
  const std::vector<GyroObservation> turns = gyro_observations(flight.imu, flight.keyframes_ns, {});
  ASSERT_EQ(turns.size(), flight.keyframes_ns.size() - 1);
  double worst = 0.0, largest_turn = 0.0;
  for (const GyroObservation& o : turns) {
    worst = std::max(worst, angle(o.delta.transpose() * flight.truth(o)));
    largest_turn = std::max(largest_turn, angle(flight.truth(o)));
    EXPECT_GT(o.sigma_rad.minCoeff(), 0.0);
  }
  RecordProperty("worst_deg", std::to_string(worst / kDeg));
  EXPECT_GT(largest_turn, 10.0 * kDeg);  // it does turn
  EXPECT_LT(worst, 0.005 * kDeg);
}

TEST(GyroReference, TheBiasComesOutThroughTheJacobian) {
  ImuModel model = ImuModel::exact();
  model.gyro_bias_radps = 0.02;  // twenty times a MEMS gyroscope's: 0.7 deg a keyframe
  const Flight biased(model);
  const Flight exact(ImuModel::exact());
  const Eigen::Vector3d bias = biased.imu[0].gyro_radps - exact.imu[0].gyro_radps;
  ASSERT_NEAR(bias.norm(), 0.02, 1e-12);
  const std::vector<GyroObservation> turns = gyro_observations(biased.imu, biased.keyframes_ns, {});
  ASSERT_FALSE(turns.empty());
  for (const GyroObservation& o : turns) {
    const Eigen::Matrix3d corrected = o.delta * exp_map(-o.bias_jacobian * bias);
    EXPECT_GT(angle(o.delta.transpose() * biased.truth(o)), 0.3 * kDeg);
    EXPECT_LT(angle(corrected.transpose() * biased.truth(o)), 0.01 * kDeg);
  }
}

TEST(GyroReference, AGapOrNoSamplesLeaveTheEdgeOut) {
  const Flight flight(ImuModel::exact());
  EXPECT_TRUE(gyro_observations({}, flight.keyframes_ns, {}).empty());
  GyroSettings off;
  off.enabled = false;
  EXPECT_TRUE(gyro_observations(flight.imu, flight.keyframes_ns, off).empty());
  // A quarter second without samples inside the third edge's span.
  std::vector<ImuSample> gappy;
  for (const ImuSample& s : flight.imu)
    if (s.stamp_ns < 1'300'000'000 || s.stamp_ns > 1'550'000'000) gappy.push_back(s);
  const std::vector<GyroObservation> turns = gyro_observations(gappy, flight.keyframes_ns, {});
  ASSERT_EQ(turns.size(), flight.keyframes_ns.size() - 2);
  for (const GyroObservation& o : turns) EXPECT_NE(o.from, 2u);
}

/// The LiDAR's turns: the truth with white noise of `noise_rad` per axis, and the graph's
/// deliberately wide 1e-3 rad sigma.
std::vector<LidarTurn> lidar_turns(const Flight& flight, const std::vector<GyroObservation>& turns,
                                   double noise_rad) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, noise_rad);
  std::vector<LidarTurn> out;
  for (const GyroObservation& o : turns) {
    LidarTurn t;
    t.rotation = flight.truth(o) * exp_map({noise(rng), noise(rng), noise(rng)});
    t.sigma_rad.setConstant(1e-3);
    out.push_back(t);
  }
  return out;
}

TEST(GyroReference, AGyroscopeWeighsLittleWhereTheLidarTurnsBetter) {
  const Flight flight(ImuModel{});  // a MEMS unit: white noise and a bias
  const std::vector<GyroObservation> modelled =
      gyro_observations(flight.imu, flight.keyframes_ns, {});
  // A car among walls: the LiDAR turns within 2e-5 rad, far better than its 1e-3.
  std::vector<GyroObservation> turns = modelled;
  const TurnAgreement good = weigh_against_lidar(&turns, lidar_turns(flight, turns, 2e-5));
  ASSERT_TRUE(good.consistent);
  EXPECT_EQ(good.edges, turns.size());
  for (size_t i = 0; i < turns.size(); ++i)
    EXPECT_GT(turns[i].sigma_rad.minCoeff(), 5.0 * modelled[i].sigma_rad.maxCoeff());
  // The bias, from the two sensors' turns, against the one the simulator drew (the same seed
  // without noise: the bias is drawn apart from it).
  ImuModel bias_only = ImuModel::exact();
  bias_only.gyro_bias_radps = ImuModel{}.gyro_bias_radps;
  const Eigen::Vector3d bias =
      Flight(bias_only).imu[0].gyro_radps - Flight(ImuModel::exact()).imu[0].gyro_radps;
  ASSERT_NEAR(bias.norm(), ImuModel{}.gyro_bias_radps, 1e-12);
  EXPECT_LT((good.bias_radps - bias).norm(), 2e-4);
  // A drone: the LiDAR turns within 1e-3 rad, as its sigma says, and worse than the
  // gyroscope: the gyroscope keeps its own sigma.
  turns = modelled;
  const TurnAgreement poor = weigh_against_lidar(&turns, lidar_turns(flight, turns, 1e-3));
  ASSERT_TRUE(poor.consistent);
  EXPECT_GT(poor.lidar_sigma_rad.minCoeff(), 5e-4);
  for (size_t i = 0; i < turns.size(); ++i)
    EXPECT_LT(turns[i].sigma_rad.maxCoeff(), 2.5 * modelled[i].sigma_rad.maxCoeff());
}

TEST(GyroReference, AGyroscopeTurnedAgainstTheSensorIsLeftOut) {
  // The IMU's samples in a frame turned 20 degrees from the sensor's (a mounting the
  // metadata got wrong): its turns disagree with the LiDAR's by a share of every turn.
  Flight flight(ImuModel::exact());
  const Eigen::Matrix3d mounting = exp_map({20.0 * kDeg, 0.0, 0.0});
  for (ImuSample& s : flight.imu) s.gyro_radps = mounting * s.gyro_radps;
  std::vector<GyroObservation> turns = gyro_observations(flight.imu, flight.keyframes_ns, {});
  const std::vector<GyroObservation> before = turns;
  const TurnAgreement agreement = weigh_against_lidar(&turns, lidar_turns(flight, turns, 1e-4));
  EXPECT_FALSE(agreement.consistent);
  for (size_t i = 0; i < turns.size(); ++i) EXPECT_EQ(turns[i].sigma_rad, before[i].sigma_rad);
}

}  // namespace
}  // namespace featsense::slam::loops
