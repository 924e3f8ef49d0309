// One home per default: the refinement's settings as the default configuration gives them
// (config.hpp, default.yaml) are the settings' own defaults, its registration included.

#include <gtest/gtest.h>

#include "featsense/slam/refine/segment_refiner.hpp"
#include "slam/settings_equality.hpp"

namespace featsense::slam::refine {
namespace {

TEST(RefineSettings, TheDefaultConfigurationGivesTheDefaults) {
  const RefineSettings configured = from_config(config::Config{});
  const RefineSettings defaults;
  EXPECT_EQ(configured.distance_m, defaults.distance_m);
  EXPECT_EQ(configured.max_scans, defaults.max_scans);
  EXPECT_EQ(configured.voxel_m, defaults.voxel_m);
  test::expect_same_vgicp(configured.vgicp, defaults.vgicp);
}

TEST(RefineSettings, TheVoxelSizeSetsTheRegistrationsVoxels) {
  config::Config config;
  config.refine.voxel_m = 0.3;
  const RefineSettings settings = from_config(config);
  EXPECT_EQ(settings.vgicp.voxel_sizes_m, (std::vector<double>{0.6, 0.3}));
  EXPECT_EQ(settings.vgicp.fitness_voxel_m, 0.6);
}

}  // namespace
}  // namespace featsense::slam::refine
