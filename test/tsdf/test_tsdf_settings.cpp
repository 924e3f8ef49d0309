// The integrator's settings from the configuration and the sensor model; one home per
// default: the default configuration gives TsdfSettings' own defaults.

#include <gtest/gtest.h>

#include <cmath>

#include "featsense/config/sensor_model.hpp"
#include "featsense/tsdf/tsdf_settings.hpp"

namespace featsense::tsdf {
namespace {

// TsdfSettings{} knows no sensor: it has neither the vertical interpolation nor sparse
// carving, which come from the sensor's beam angles.
TEST(TsdfSettings, TheDefaultConfigurationGivesTheDefaults) {
  config::MapConfig map;
  map.vertical_interpolation = false;
  map.sparse_carving = false;
  const TsdfSettings configured = TsdfSettings::from_config(map, config::sensor_preset("os1-128"));
  const TsdfSettings defaults;
  EXPECT_EQ(configured.voxel_size_m, defaults.voxel_size_m);
  EXPECT_EQ(configured.truncation_m, defaults.truncation_m);
  EXPECT_EQ(configured.max_weight, defaults.max_weight);
  EXPECT_EQ(configured.map_size_m, defaults.map_size_m);
  EXPECT_EQ(configured.interpolation_slope, defaults.interpolation_slope);
  EXPECT_EQ(configured.reduce_points_per_voxel, defaults.reduce_points_per_voxel);
  EXPECT_EQ(configured.dense_range_m, defaults.dense_range_m);
  EXPECT_EQ(configured.carve_free_space, defaults.carve_free_space);
}

TEST(TsdfSettings, InterpolationFollowsTheSensorsBeamSpacingOrIsOff) {
  const config::SensorModel os1 = config::sensor_preset("os1-128");
  config::MapConfig map;
  const TsdfSettings on = TsdfSettings::from_config(map, os1);
  EXPECT_NEAR(on.interpolation_slope, std::tan(os1.vertical_fov_rad() / os1.beams), 1e-7);
  const TsdfSettings vlp = TsdfSettings::from_config(map, config::sensor_preset("vlp16"));
  EXPECT_GT(vlp.interpolation_slope, 5.0f * on.interpolation_slope) << "16 beams over 30 deg";
  map.vertical_interpolation = false;
  EXPECT_EQ(TsdfSettings::from_config(map, os1).interpolation_slope, 0.0f);
}

TEST(TsdfSettings, SparseCarvingRangeFollowsTheCoarsestAngleBetweenRays) {
  config::MapConfig map;
  const config::SensorModel os1 = config::sensor_preset("os1-128");
  // Columns 2 pi / 1024 = 6.14 mrad apart, beams about the same: 6.4 cm / (2 x 6.1 mrad).
  const TsdfSettings s = TsdfSettings::from_config(map, os1);
  EXPECT_GT(s.dense_range_m, 4.6f);
  EXPECT_LT(s.dense_range_m, 0.064f / (2.0f * 2.0f * 3.14159265f / 1024.0f) + 1e-4f);
  // 16 beams 2 deg apart: the beams, not the columns, set it: 6.4 cm / (2 x 34.9 mrad).
  const TsdfSettings vlp = TsdfSettings::from_config(map, config::sensor_preset("vlp16"));
  EXPECT_NEAR(vlp.dense_range_m, 0.064 / (2.0 * 2.0 * 3.14159265 / 180.0), 0.01);
  map.voxel_size_m = 0.128;
  EXPECT_NEAR(TsdfSettings::from_config(map, os1).dense_range_m, 2.0f * s.dense_range_m, 1e-3);
  map.sparse_carving = false;
  EXPECT_EQ(TsdfSettings::from_config(map, os1).dense_range_m, 0.0f);
  EXPECT_TRUE(TsdfSettings::from_config(map, os1).carve_free_space);
  map.carve_free_space = false;
  EXPECT_FALSE(TsdfSettings::from_config(map, os1).carve_free_space);
}

TEST(TsdfSettings, SizesAndWeightsComeFromTheMapConfig) {
  config::MapConfig map;
  map.voxel_size_m = 0.1;
  map.truncation_m = 0.3;
  map.max_weight = 20.0;
  map.size_m = {8.0, 8.0, 4.0};
  const TsdfSettings s = TsdfSettings::from_config(map, config::sensor_preset("os1-64"));
  EXPECT_FLOAT_EQ(s.voxel_size_m, 0.1f);
  EXPECT_FLOAT_EQ(s.truncation_m, 0.3f);
  EXPECT_EQ(s.max_weight_fixed(), 20u * 64u);
  // 80 voxels = 10 bricks -> 11 (odd); 40 voxels = 5 bricks.
  EXPECT_EQ(s.map_dim().x, 88);
  EXPECT_EQ(s.map_dim().z, 40);
}

}  // namespace
}  // namespace featsense::tsdf
