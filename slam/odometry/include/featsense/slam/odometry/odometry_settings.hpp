#pragma once
/// The odometry's settings: plain fields, their defaults those of config.hpp, their reasons in
/// config/default.yaml.

#include "featsense/config/config.hpp"

namespace featsense::slam::odometry {

namespace detail {
/// The odometry settings of config/default.yaml, where OdometrySettings' defaults come from.
inline constexpr config::OdometryConfig kDefaultOdometry{};
}  // namespace detail

/// Default-constructed: the default configuration's (a test keeps from_config(Config{}) equal
/// to it).
struct OdometrySettings {
  /// Outer loops: re-associate, then a few solver iterations.
  int optimization_steps = detail::kDefaultOdometry.optimization_steps;
  /// Ceres iterations per outer loop, as F-LOAM; no key.
  int solver_iterations = 4;
  double edge_voxel_m = detail::kDefaultOdometry.edge_voxel_m;
  double surface_voxel_m = detail::kDefaultOdometry.surface_voxel_m;
  double map_radius_m = detail::kDefaultOdometry.map_radius_m;
  double max_correspondence_distance_m = detail::kDefaultOdometry.max_correspondence_distance_m;
  /// A surface point's neighbours all lie within this of their plane (fit_plane).
  double plane_tolerance_m = detail::kDefaultOdometry.plane_tolerance_m;
  double huber_loss_m = detail::kDefaultOdometry.huber_loss_m;
  double degeneracy_threshold = detail::kDefaultOdometry.degeneracy_threshold;
  double max_speed_m_s = detail::kDefaultOdometry.max_speed_m_s;
  double max_turn_rate_rad_s = detail::kDefaultOdometry.max_turn_rate_rad_s;
  /// A fit this many times the recent median is searched again from turned starts.
  double poor_fit_ratio = detail::kDefaultOdometry.poor_fit_ratio;
  /// The largest turn of the prediction that search tries, degrees; 0: no search.
  double turn_search_deg = detail::kDefaultOdometry.turn_search_deg;
  /// Register the features deskewed to the scan's stamp with the motion being estimated
  /// (re-deskewed at every outer loop); false: as measured.
  bool deskew = detail::kDefaultOdometry.deskew;
  /// Hold the pose while the sensor stands still (StandDetector).
  bool hold_still = detail::kDefaultOdometry.hold_still;
  /// Turn the prediction by the gyroscope where the scans carry IMU samples (see
  /// gyro_rotation.hpp); false: constant velocity only. No key: always on, off for tests.
  bool gyro_prediction = true;
  /// Scans in a row whose motion stays within the registration's noise before a stand starts,
  /// and registered beyond it before the stand ends (one outlier does not end one). No key.
  int stand_enter_scans = 1;
  int stand_leave_scans = 2;
};

/// The settings of config's odometry section.
OdometrySettings from_config(const config::Config& config);

}  // namespace featsense::slam::odometry
