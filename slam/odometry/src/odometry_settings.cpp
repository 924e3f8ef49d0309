#include "featsense/slam/odometry/odometry_settings.hpp"

namespace featsense::slam::odometry {

OdometrySettings from_config(const config::Config& config) {
  const config::OdometryConfig& c = config.odometry;
  OdometrySettings s;
  s.optimization_steps = c.optimization_steps;
  s.edge_voxel_m = c.edge_voxel_m;
  s.surface_voxel_m = c.surface_voxel_m;
  s.map_radius_m = c.map_radius_m;
  s.max_correspondence_distance_m = c.max_correspondence_distance_m;
  s.plane_tolerance_m = c.plane_tolerance_m;
  s.huber_loss_m = c.huber_loss_m;
  s.degeneracy_threshold = c.degeneracy_threshold;
  s.max_speed_m_s = c.max_speed_m_s;
  s.max_turn_rate_rad_s = c.max_turn_rate_rad_s;
  s.poor_fit_ratio = c.poor_fit_ratio;
  s.turn_search_deg = c.turn_search_deg;
  s.deskew = c.deskew;
  s.hold_still = c.hold_still;
  return s;
}

}  // namespace featsense::slam::odometry
