#pragma once
/// The sensor's motion within one sweep, for deskewing: the constant velocity between the last
/// stamp and this one, bent by what the gyroscope measured where the scan carries IMU samples.
///
/// Why the gyroscope: a car entering a corner turns faster and faster (about 130 deg/s^2 in a
/// town). At constant velocity the sweep's last points are then left alpha T^2 behind (1.3 deg
/// over a 0.1 s sweep), and the registration splits that into a yaw error of the pose at the
/// stamp and a twisted sweep in the map. The gyroscope measures the change of the turn rate
/// within the sweep. Its bias (0.1-1 deg/s for a MEMS gyroscope) cancels: only the rate's
/// departure from its own mean over the period before the stamp is used, so the LiDAR's motion
/// gives the mean rate and the gyroscope the shape of the turn.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

#include "featsense/slam/imu_sample.hpp"

namespace featsense::slam {

/// What the gyroscope adds to a constant-velocity rotation: at t seconds after the stamp, the
/// integral from the stamp to t of the measured rate less its mean over the period whose
/// motion the constant velocity is (the previous stamp to this one; for the first scan, this
/// one to the next), as a rotation vector in the sensor frame. The rate is taken as linear
/// between samples and constant beyond the first and the last.
class GyroTwist {
 public:
  /// No twist: the motion stays at constant velocity.
  GyroTwist() = default;

  /// From the samples of two consecutive sweeps (each in time order, stamps in the scans'
  /// clock), the period [period_from_ns, period_to_ns] and the stamp. Empty where they leave a
  /// gap longer than half the period anywhere over it and the first half of the sweep, or
  /// where the period is not positive: then nothing is known about the turn's shape.
  static GyroTwist from_samples(const std::vector<ImuSample>& earlier,
                                const std::vector<ImuSample>& later, int64_t period_from_ns,
                                int64_t period_to_ns, int64_t stamp_ns);

  bool empty() const { return times_s_.empty(); }
  /// The rotation vector at t seconds after the stamp (zero at the stamp; zero when empty).
  Eigen::Vector3d at(double t_s) const;

 private:
  /// Per sample: its time after the stamp, its rate less the mean, and the twist there.
  std::vector<double> times_s_;
  std::vector<Eigen::Vector3d> rates_;
  std::vector<Eigen::Vector3d> twists_;
};

/// One sweep's motion: the sensor at the stamp <- the sensor t seconds after it.
class SweepMotion {
 public:
  /// Not moving: every column at the stamp's pose.
  SweepMotion() = default;
  /// `motion`: the previous stamp's sensor <- this stamp's, made in `period_s`.
  SweepMotion(const Eigen::Isometry3d& motion, double period_s, GyroTwist twist = {});

  /// The rotation of the constant velocity turned further by the twist (exp(w t / period +
  /// twist(t))), the translation at constant velocity; identity when not moving. Without a
  /// twist it is exactly motion_fraction(motion, t / period).
  Eigen::Isometry3d at(double t_s) const;

  bool moving() const { return period_s_ > 0.0; }
  const Eigen::Isometry3d& motion() const { return motion_; }
  double period_s() const { return period_s_; }
  const GyroTwist& twist() const { return twist_; }

 private:
  Eigen::Isometry3d motion_ = Eigen::Isometry3d::Identity();
  double period_s_ = 0.0;
  Eigen::Vector3d rotation_vector_ = Eigen::Vector3d::Zero();  ///< of the motion's rotation
  GyroTwist twist_;
};

}  // namespace featsense::slam
