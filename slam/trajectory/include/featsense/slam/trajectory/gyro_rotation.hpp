#pragma once
/// The sensor's turn over a period as the gyroscope measured it, and the constant-velocity
/// prediction corrected by it.
///
/// Why: a drone or a hand-held sensor that whips round a corner changes its turn rate by
/// hundreds of degrees per second squared (the simulated lab drone: 90 to 166 deg/s within
/// 0.3 s). A prediction that repeats the last scan's motion is then degrees off and the
/// registration can settle in a wrong minimum. The gyroscope measures the turn itself; its
/// bias (0.1-1 deg/s on a MEMS unit) cancels against the LiDAR's last motion, as in
/// GyroTwist: only the change of the measured turn from one period to the next is used.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <vector>

#include "featsense/slam/imu_sample.hpp"

namespace featsense::slam {

/// The rotation over [from_ns, to_ns] (the sensor at from_ns <- the sensor at to_ns) that the
/// samples of two consecutive sweeps (each in time order, the scans' clock) integrate to, the
/// rate linear between samples. Empty where the period is not positive or the samples leave a
/// gap longer than half the period anywhere over it (the ends included).
std::optional<Eigen::Matrix3d> gyro_rotation(const std::vector<ImuSample>& earlier,
                                             const std::vector<ImuSample>& later, int64_t from_ns,
                                             int64_t to_ns);

/// A turn the gyroscope measured, and how it moves with a constant bias b of the rates: the
/// turn with the bias taken out is rotation Exp(-bias_jacobian b), to first order.
struct GyroTurn {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d bias_jacobian = Eigen::Matrix3d::Zero();
};

/// gyro_rotation's turn with its bias Jacobian, and a gap allowed of `max_gap_s` seconds
/// (gyro_rotation allows half the period): empty where the period is not positive or the
/// samples leave a longer gap anywhere over it (the ends included).
std::optional<GyroTurn> gyro_turn(const std::vector<ImuSample>& earlier,
                                  const std::vector<ImuSample>& later, int64_t from_ns,
                                  int64_t to_ns, double max_gap_s);

/// The constant-velocity prediction `predicted` (last_motion scaled to this period) with its
/// rotation replaced by the gyroscope's turn over this period `turn_now`, corrected by the
/// LiDAR's: the gyroscope's error over the last period (`turn_before` against
/// `last_motion`'s rotation, a bias) scaled by `ratio` (this period over the last). The
/// translation stays the prediction's.
Eigen::Isometry3d gyro_corrected_prediction(const Eigen::Isometry3d& predicted,
                                            const Eigen::Isometry3d& last_motion,
                                            const Eigen::Matrix3d& turn_before,
                                            const Eigen::Matrix3d& turn_now, double ratio);

}  // namespace featsense::slam
