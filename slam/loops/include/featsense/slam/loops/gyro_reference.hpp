#pragma once
/// The gyroscope's turn between keyframes as an edge of the pose graph. A LiDAR's relative
/// rotations between keyframes carry an error of a few hundredths of a degree each, which the
/// graph lets add up: a drone's map can lean by a few tenths of a degree between two places
/// that gravity levels, and the accelerometer's bias can pass for such a lean. A MEMS
/// gyroscope integrated over the second between two keyframes turns within about 0.015 deg
/// (white noise of 0.003 rad/s per 100 Hz sample), once its constant bias, a graph variable,
/// is known:
///   R_from^T R_to = delta (b) = delta(0) Exp(-J b),
/// with delta(0) the samples' rotations chained and J how the chain moves with the bias.

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/imu_sample.hpp"

namespace featsense::slam::loops {

struct GyroSettings {
  bool enabled = config::LoopConfig{}.gyro;  ///< loop.gyro
  /// The gyroscope's white noise per sample, rad/s.
  double noise_radps = 0.003;
  /// What the model leaves out, radians: a floor per edge, a share of the turn (the IMU's
  /// mounting against the LiDAR's, a scale error) and the turn rate's change times this many
  /// seconds (the two clocks' offset).
  double min_sigma_rad = 2e-4;
  double turn_fraction = 0.005;
  double clock_offset_s = 0.002;
  /// The prior on the gyroscope's bias, rad/s per axis.
  double bias_prior_radps = 0.02;
  /// A gap between samples longer than this many sample periods leaves the edge out.
  double max_gap_periods = 5.0;
};

/// The rotation the gyroscope measured from keyframe `from` to keyframe `to`.
struct GyroObservation {
  size_t from = 0;
  size_t to = 0;
  Eigen::Matrix3d delta = Eigen::Matrix3d::Identity();      ///< R_from^T R_to with no bias
  Eigen::Matrix3d bias_jacobian = Eigen::Matrix3d::Zero();  ///< J: delta(b) = delta Exp(-J b)
  /// The standard deviation about each axis of `from`'s frame, radians: the model's (noise,
  /// floor, mounting, clock), raised by weigh_against_lidar where the LiDAR turns better.
  Eigen::Vector3d sigma_rad = Eigen::Vector3d::Ones();
  /// The white noise and floor alone, radians (what the gyroscope errs by on any mounting).
  double noise_rad = 1.0;
};

/// The LiDAR's turn between the same two keyframes (the odometry edge's), and the standard
/// deviation about each axis that the pose graph gives it.
struct LidarTurn {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d sigma_rad = Eigen::Vector3d::Ones();
};

/// How the gyroscope and the LiDAR agreed, per axis of the keyframes' frames.
struct TurnAgreement {
  size_t edges = 0;
  Eigen::Vector3d bias_radps = Eigen::Vector3d::Zero();        ///< the gyroscope's, least squares
  Eigen::Vector3d disagreement_rad = Eigen::Vector3d::Zero();  ///< robust RMS, bias removed
  Eigen::Vector3d lidar_sigma_rad = Eigen::Vector3d::Zero();   ///< what is left for the LiDAR
  /// False where the two disagree by far more than either claims (an IMU mounted otherwise
  /// than its rotation into the sensor frame says, a clock apart): the edges are left out.
  bool consistent = true;
};

/// The gyroscope's rotations between consecutive keyframes stamped `keyframe_stamps_ns` (node
/// i = keyframe i), from `samples` (time order). A pair whose span the samples do not cover
/// without a gap, or whose second stamp is not after the first (two sessions), gets none.
std::vector<GyroObservation> gyro_observations(const std::vector<ImuSample>& samples,
                                               const std::vector<int64_t>& keyframe_stamps_ns,
                                               const GyroSettings& settings);

/// Weighs each edge of `turns` against the LiDAR's turns `lidar` (same order, same nodes) as
/// their disagreement says the two compare. The graph's LiDAR edges carry a deliberately
/// wide rotation sigma (loops must be able to bend them); the LiDAR's real error differs by
/// scene twenty-fold: a car among walls turns within a few thousandths of a degree per
/// keyframe, a drone's sweeps within a few hundredths. The disagreement, the gyroscope's bias
/// removed, is sqrt(lidar^2 + noise^2) per axis; with the gyroscope's noise known, what is
/// left is the LiDAR's error. Each gyroscope sigma is then raised so that it weighs against
/// the graph's LiDAR sigma as the gyroscope weighs against the LiDAR's real error (never
/// lowered): where the LiDAR turns better than its sigma says, the gyroscope hardly pulls.
/// Where they disagree by more than kInconsistent times what both claim together, the result
/// says so (`consistent` false) and `turns` is left as it was.
TurnAgreement weigh_against_lidar(std::vector<GyroObservation>* turns,
                                  const std::vector<LidarTurn>& lidar);

}  // namespace featsense::slam::loops
