#pragma once
/// The pose of a trajectory at any instant: between two poses the translation is linear and
/// the rotation a slerp, so a scan's points can each be placed by the pose at their own time.
/// A little beyond the ends the motion of the nearest two poses is continued (the last scan
/// of a recording outlasts the last pose that was stamped at its start).

#include <Eigen/Geometry>

#include <cstdint>
#include <optional>

#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

class PoseInterpolator {
 public:
  /// `max_extrapolation_s`: how far beyond the first and last stamp a pose is still given.
  /// Throws TrajectoryError when the trajectory is empty or has no stamps.
  explicit PoseInterpolator(Trajectory trajectory, double max_extrapolation_s = 0.2);

  /// T_map_sensor at `stamp_ns`, or nullopt when it lies outside the trajectory's time range
  /// (widened by the extrapolation allowance).
  std::optional<Eigen::Isometry3d> at(int64_t stamp_ns) const;

  const Trajectory& trajectory() const { return trajectory_; }

 private:
  Trajectory trajectory_;
  int64_t max_extrapolation_ns_;
};

/// The pose between `a` (f = 0) and `b` (f = 1); f outside [0, 1] continues the motion.
Eigen::Isometry3d interpolate_pose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                   double f);

/// The fraction `s` of a rigid motion made at constant velocity: interpolate_pose from the
/// identity (s < 0: before the motion began, s > 1: continued beyond it).
Eigen::Isometry3d motion_fraction(const Eigen::Isometry3d& motion, double s);

}  // namespace featsense::slam
