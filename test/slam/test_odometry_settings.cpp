// One home per default: the odometry's settings as the default configuration gives them
// (config.hpp, default.yaml) are the settings' own defaults, and every key reaches its field.

#include <gtest/gtest.h>

#include "featsense/slam/odometry/odometry_settings.hpp"

namespace featsense::slam::odometry {
namespace {

void expect_same(const OdometrySettings& a, const OdometrySettings& b) {
  EXPECT_EQ(a.optimization_steps, b.optimization_steps);
  EXPECT_EQ(a.solver_iterations, b.solver_iterations);
  EXPECT_EQ(a.edge_voxel_m, b.edge_voxel_m);
  EXPECT_EQ(a.surface_voxel_m, b.surface_voxel_m);
  EXPECT_EQ(a.map_radius_m, b.map_radius_m);
  EXPECT_EQ(a.max_correspondence_distance_m, b.max_correspondence_distance_m);
  EXPECT_EQ(a.huber_loss_m, b.huber_loss_m);
  EXPECT_EQ(a.degeneracy_threshold, b.degeneracy_threshold);
  EXPECT_EQ(a.max_speed_m_s, b.max_speed_m_s);
  EXPECT_EQ(a.max_turn_rate_rad_s, b.max_turn_rate_rad_s);
  EXPECT_EQ(a.poor_fit_ratio, b.poor_fit_ratio);
  EXPECT_EQ(a.turn_search_deg, b.turn_search_deg);
  EXPECT_EQ(a.deskew, b.deskew);
  EXPECT_EQ(a.hold_still, b.hold_still);
}

TEST(OdometrySettings, TheDefaultConfigurationGivesTheDefaults) {
  expect_same(from_config(config::Config{}), OdometrySettings{});
}

TEST(OdometrySettings, EveryKeyReachesItsSetting) {
  config::Config config;
  config::OdometryConfig& c = config.odometry;
  c.optimization_steps = 5;
  c.edge_voxel_m = 0.25;
  c.surface_voxel_m = 0.5;
  c.map_radius_m = 40.0;
  c.max_correspondence_distance_m = 1.5;
  c.huber_loss_m = 0.2;
  c.degeneracy_threshold = 0.05;
  c.max_speed_m_s = 20.0;
  c.max_turn_rate_rad_s = 2.0;
  c.poor_fit_ratio = 3.0;
  c.turn_search_deg = 12.0;
  c.deskew = false;
  c.hold_still = false;

  OdometrySettings expected;
  expected.optimization_steps = 5;
  expected.edge_voxel_m = 0.25;
  expected.surface_voxel_m = 0.5;
  expected.map_radius_m = 40.0;
  expected.max_correspondence_distance_m = 1.5;
  expected.huber_loss_m = 0.2;
  expected.degeneracy_threshold = 0.05;
  expected.max_speed_m_s = 20.0;
  expected.max_turn_rate_rad_s = 2.0;
  expected.poor_fit_ratio = 3.0;
  expected.turn_search_deg = 12.0;
  expected.deskew = false;
  expected.hold_still = false;
  expect_same(from_config(config), expected);
}

}  // namespace
}  // namespace featsense::slam::odometry
