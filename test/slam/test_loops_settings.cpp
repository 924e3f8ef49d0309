// One home per default: the loop closure's settings as the default configuration gives them
// (config.hpp, default.yaml) are the settings' own defaults.

#include <gtest/gtest.h>

#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/loops/relocalizer.hpp"
#include "slam/settings_equality.hpp"

namespace featsense::slam::loops {
namespace {

TEST(LoopSettings, TheDefaultConfigurationGivesTheDefaults) {
  const LoopSettings configured = from_config(config::Config{});
  const LoopSettings defaults;
  EXPECT_EQ(configured.keyframe_distance_m, defaults.keyframe_distance_m);
  EXPECT_EQ(configured.keyframe_angle_deg, defaults.keyframe_angle_deg);
  EXPECT_EQ(configured.min_separation_s, defaults.min_separation_s);
  EXPECT_EQ(configured.min_separation_m, defaults.min_separation_m);
  EXPECT_EQ(configured.max_descriptor_distance, defaults.max_descriptor_distance);
  EXPECT_EQ(configured.max_fitness_m, defaults.max_fitness_m);
  EXPECT_EQ(configured.min_inlier_fraction, defaults.min_inlier_fraction);
  EXPECT_EQ(configured.drift_per_m, defaults.drift_per_m);
  EXPECT_EQ(configured.gravity.enabled, defaults.gravity.enabled);
  EXPECT_EQ(configured.gravity.window_s, defaults.gravity.window_s);
  test::expect_same_vgicp(configured.vgicp, defaults.vgicp);
}

TEST(LoopSettings, EveryKeyReachesItsSetting) {
  config::Config config;
  config.loop.keyframe_distance_m = 2.5;
  config.loop.min_inlier_fraction = 0.7;
  config.loop.drift = 0.05;
  config.loop.gravity = false;
  const LoopSettings settings = from_config(config);
  EXPECT_EQ(settings.keyframe_distance_m, 2.5);
  EXPECT_EQ(settings.min_inlier_fraction, 0.7);
  EXPECT_EQ(settings.drift_per_m, 0.05);
  EXPECT_FALSE(settings.gravity.enabled);
}

TEST(RelocalizeSettings, TheDefaultConfigurationGivesTheDefaults) {
  const RelocalizeSettings configured = relocalize_from_config(config::Config{});
  const RelocalizeSettings defaults;
  EXPECT_EQ(configured.confirmations, defaults.confirmations);
  EXPECT_EQ(configured.loop.min_inlier_fraction, defaults.loop.min_inlier_fraction);
  EXPECT_EQ(configured.loop.max_fitness_m, defaults.loop.max_fitness_m);
  test::expect_same_vgicp(configured.loop.vgicp, defaults.loop.vgicp);
}

TEST(RelocalizeSettings, ItsKeysAndTheLoopsReachTheirSettings) {
  config::Config config;
  config.relocalize.confirmations = 3;
  config.loop.max_fitness_m = 0.2;
  const RelocalizeSettings settings = relocalize_from_config(config);
  EXPECT_EQ(settings.confirmations, 3u);
  EXPECT_EQ(settings.loop.max_fitness_m, 0.2);
}

}  // namespace
}  // namespace featsense::slam::loops
