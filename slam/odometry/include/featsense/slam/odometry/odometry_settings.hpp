#pragma once
/// The odometry's settings: plain fields, their defaults and reasons in config/default.yaml.

#include "featsense/config/config.hpp"

namespace featsense::slam::odometry {

struct OdometrySettings {
  int optimization_steps = 0;  ///< outer loops: re-associate, then a few solver iterations
  int solver_iterations = 0;   ///< Ceres iterations per outer loop
  double edge_voxel_m = 0.0;
  double surface_voxel_m = 0.0;
  double map_radius_m = 0.0;
  double max_correspondence_distance_m = 0.0;
  double huber_loss_m = 0.0;
  double degeneracy_threshold = 0.0;
  double max_speed_m_s = 0.0;
  double max_turn_rate_rad_s = 0.0;
  /// Register the features deskewed to the scan's stamp with the motion being estimated
  /// (re-deskewed at every outer loop); false: as measured.
  bool deskew = false;
};

/// The settings of config's odometry section (4 solver iterations per outer loop, as F-LOAM).
OdometrySettings from_config(const config::Config& config);

}  // namespace featsense::slam::odometry
