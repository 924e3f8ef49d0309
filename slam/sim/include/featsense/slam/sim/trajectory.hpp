#pragma once
/// Sensor paths for the simulator: smooth splines through waypoints at constant speed, or
/// poses interpolated between the samples of a trajectory file.

#include <Eigen/Geometry>

#include <memory>
#include <string>
#include <vector>

#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

/// A pose over time. Times are seconds from the trajectory's start; poses map sensor
/// coordinates into the map (T_map_sensor), Z up.
class PoseCurve {
 public:
  virtual ~PoseCurve() = default;
  /// Seconds from the start to the last pose.
  virtual double duration_s() const = 0;
  /// T_map_sensor at `t_s` seconds after the start (clamped to [0, duration]).
  virtual Eigen::Isometry3d pose(double t_s) const = 0;
};

/// One stamped pose of a TUM file: "t x y z qx qy qz qw", t in seconds.
struct StampedPose {
  double t_s = 0.0;
  Eigen::Isometry3d T_map_sensor = Eigen::Isometry3d::Identity();
};

/// A C2 cubic spline (natural end conditions, chord-length knots) through `waypoints_m`
/// (map frame, metres), travelled at `speed_mps` exactly (arc-length parameterised).
/// Yaw follows the direction of travel; with `tilt` the sensor also rolls into turns (by
/// the lateral acceleration against gravity) and pitches with climbs. Throws
/// std::invalid_argument for fewer than two waypoints, repeated waypoints or speed <= 0.
std::unique_ptr<PoseCurve> make_spline_trajectory(const std::vector<Eigen::Vector3d>& waypoints_m,
                                                  double speed_mps, bool tilt = false);

/// Poses interpolated between samples (linear in position, slerp in rotation); times are
/// taken relative to the first sample. Throws std::invalid_argument for fewer than two
/// samples or times that do not increase.
std::unique_ptr<PoseCurve> make_sampled_trajectory(const std::vector<StampedPose>& poses);

/// `path` with a stop: from `at_s` seconds on the sensor slows to a stand over `ramp_s`
/// (speed falling as a half cosine, so acceleration stays finite: a car's braking, a walker's
/// pause), stands for `for_s` and speeds up again over `ramp_s` to continue the path where it
/// stopped. The path is followed as before, only in time warped; it lasts for_s + ramp_s
/// longer. Throws std::invalid_argument for a stop outside the path (at_s < ramp_s or past
/// its end), for_s <= 0 or ramp_s <= 0.
std::unique_ptr<PoseCurve> make_paused_trajectory(std::unique_ptr<PoseCurve> path, double at_s,
                                                  double for_s, double ramp_s);

/// The poses of a trajectory file (trajectory_io.hpp reads and writes TUM and KITTI), and back.
std::vector<StampedPose> to_stamped_poses(const Trajectory& trajectory);
Trajectory to_trajectory(const std::vector<StampedPose>& poses);

}  // namespace featsense::slam
