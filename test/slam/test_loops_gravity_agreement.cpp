#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdint>
#include <vector>

#include "featsense/slam/loops/gravity_reference.hpp"

namespace featsense::slam::loops {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kGravity = 9.81;

/// Keyframes turning through every heading with a little roll and pitch, in a map frame tilted
/// by 0.2 deg, read by an accelerometer with a constant bias; each window's up turned further
/// by `scatter_rad` per axis (normal, drawn from a fixed sequence), as an odometry's
/// acceleration errs.
struct Keyframes {
  std::vector<Eigen::Matrix3d> R_map_node;
  std::vector<GravityObservation> observations;

  Keyframes(size_t count, double scatter_rad, double model_sigma_rad, double shared) {
    const Eigen::Matrix3d tilt =
        Eigen::AngleAxisd(0.2 * kDeg, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
    const Eigen::Vector3d bias(0.03, -0.02, 0.01);
    uint64_t state = 99;
    const auto uniform = [&state]() {
      state = state * 6364136223846793005ULL + 1442695040888963407ULL;
      return (static_cast<double>(state >> 11) + 0.5) / static_cast<double>(1ULL << 53);
    };
    const auto normal = [&uniform]() {
      return std::sqrt(-2.0 * std::log(uniform())) * std::cos(2.0 * M_PI * uniform());
    };
    for (size_t i = 0; i < count; ++i) {
      const double k = static_cast<double>(i);
      const Eigen::Matrix3d R =
          (Eigen::AngleAxisd(k * 0.3, Eigen::Vector3d::UnitZ()) *
           Eigen::AngleAxisd(0.02 * std::sin(k), Eigen::Vector3d::UnitX()) *
           Eigen::AngleAxisd(0.03 * std::cos(0.7 * k), Eigen::Vector3d::UnitY()))
              .toRotationMatrix();
      R_map_node.push_back(R);
      const Eigen::Matrix3d error =
          (Eigen::AngleAxisd(scatter_rad * normal(), Eigen::Vector3d::UnitX()) *
           Eigen::AngleAxisd(scatter_rad * normal(), Eigen::Vector3d::UnitY()))
              .toRotationMatrix();
      GravityObservation o;
      o.node = i;
      // Up in the node's frame: the true vertical (the map frame tilted) through the node's
      // rotation, plus the bias the accelerometer adds.
      o.mean_force =
          R.transpose() * error * tilt.transpose() * Eigen::Vector3d::UnitZ() * kGravity + bias;
      o.shared = shared;
      o.sigma_rad = model_sigma_rad * std::sqrt(shared);
      observations.push_back(o);
    }
  }
};

TEST(GravityAgreement, ObservationsThatAgreeKeepTheirSigmas) {
  Keyframes keyframes(60, 0.0, 1e-3, 4.0);
  const std::vector<GravityObservation> before = keyframes.observations;
  const GravityAgreement agreement =
      weigh_gravity_against_lidar(&keyframes.observations, keyframes.R_map_node, 0.2);
  EXPECT_EQ(agreement.observations, 60u);
  EXPECT_NEAR(agreement.model_rad, 1e-3, 1e-12);
  // One common tilt and bias explain them all.
  EXPECT_LT(agreement.scatter_rad, 1e-5);
  for (size_t i = 0; i < before.size(); ++i)
    EXPECT_DOUBLE_EQ(keyframes.observations[i].sigma_rad, before[i].sigma_rad);
}

TEST(GravityAgreement, AScatterBeyondTheModelRaisesEverySigmaToIt) {
  const double scatter = 0.05 * kDeg;
  Keyframes keyframes(400, scatter, 1e-4, 4.0);
  const GravityAgreement agreement =
      weigh_gravity_against_lidar(&keyframes.observations, keyframes.R_map_node, 0.2);
  RecordProperty("scatter_deg", std::to_string(agreement.scatter_rad / kDeg));
  EXPECT_NEAR(agreement.scatter_rad, scatter, 0.15 * scatter);
  for (const GravityObservation& o : keyframes.observations)
    EXPECT_DOUBLE_EQ(o.sigma_rad, agreement.scatter_rad * 2.0);  // sqrt(shared)
}

TEST(GravityAgreement, AModelAboveTheScatterIsNotLowered) {
  Keyframes keyframes(100, 0.01 * kDeg, 0.1 * kDeg, 1.0);
  const std::vector<GravityObservation> before = keyframes.observations;
  const GravityAgreement agreement =
      weigh_gravity_against_lidar(&keyframes.observations, keyframes.R_map_node, 0.2);
  EXPECT_LT(agreement.scatter_rad, agreement.model_rad);
  for (size_t i = 0; i < before.size(); ++i)
    EXPECT_DOUBLE_EQ(keyframes.observations[i].sigma_rad, before[i].sigma_rad);
}

TEST(GravityAgreement, TooFewObservationsOrAMissingNodeAreLeftAsModelled) {
  Keyframes few(5, 0.1 * kDeg, 1e-4, 1.0);
  const std::vector<GravityObservation> before = few.observations;
  EXPECT_EQ(weigh_gravity_against_lidar(&few.observations, few.R_map_node, 0.2).observations, 0u);
  for (size_t i = 0; i < before.size(); ++i)
    EXPECT_DOUBLE_EQ(few.observations[i].sigma_rad, before[i].sigma_rad);

  Keyframes missing(30, 0.1 * kDeg, 1e-4, 1.0);
  missing.R_map_node.pop_back();
  EXPECT_EQ(
      weigh_gravity_against_lidar(&missing.observations, missing.R_map_node, 0.2).observations, 0u);
}

}  // namespace
}  // namespace featsense::slam::loops
