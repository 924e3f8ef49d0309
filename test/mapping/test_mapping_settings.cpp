// One home per default: what the engine takes from the configuration, a pass's settings and
// how a recording is read, is by default exactly what the structs hold, and every key reaches
// its field.

#include <gtest/gtest.h>

#include "featsense/mapping/localizer.hpp"
#include "featsense/mapping/map_pass.hpp"
#include "featsense/mapping/recording.hpp"

namespace featsense::mapping {
namespace {

void expect_same(const slam::SourceOptions& a, const slam::SourceOptions& b) {
  EXPECT_EQ(a.meta_path, b.meta_path);
  EXPECT_EQ(a.topic, b.topic);
  EXPECT_EQ(a.sensor_preset, b.sensor_preset);
  EXPECT_EQ(a.min_range_m, b.min_range_m);
  EXPECT_EQ(a.max_range_m, b.max_range_m);
  EXPECT_EQ(a.self_box, b.self_box);
  EXPECT_EQ(a.times_from_azimuth, b.times_from_azimuth);
  EXPECT_EQ(a.velodyne_calibration, b.velodyne_calibration);
  EXPECT_EQ(a.scan_cut_deg, b.scan_cut_deg);
  EXPECT_EQ(a.imu, b.imu);
  EXPECT_EQ(a.imu_topic, b.imu_topic);
  EXPECT_EQ(a.imu_rotation_deg, b.imu_rotation_deg);
}

TEST(MappingSettings, TheDefaultConfigurationGivesTheDefaultPass) {
  const PassSettings configured = pass_settings(config::Config{});
  const PassSettings defaults;
  EXPECT_EQ(configured.flush_interval_s, defaults.flush_interval_s);
  EXPECT_EQ(configured.drop_mixed_pixels, defaults.drop_mixed_pixels);
  EXPECT_EQ(configured.integrate, defaults.integrate);
  EXPECT_FALSE(configured.refine);
  EXPECT_FALSE(configured.loops);
  EXPECT_FALSE(configured.relocalize);
}

TEST(MappingSettings, ThePassKeysReachTheirSettings) {
  config::Config config;
  config.map.flush_interval_s = 5.0;
  config.sensor.drop_mixed_pixels = false;
  const PassSettings settings = pass_settings(config);
  EXPECT_EQ(settings.flush_interval_s, 5.0);
  EXPECT_FALSE(settings.drop_mixed_pixels);
}

TEST(MappingSettings, TheDefaultConfigurationReadsRecordingsAsTheReadersDefaultDo) {
  expect_same(source_options(config::Config{}, std::nullopt, std::nullopt), slam::SourceOptions{});
}

TEST(MappingSettings, EverySensorKeyReachesTheReader) {
  config::Config config;
  config.sensor.preset = "vlp16";
  config.sensor.min_range_m = 0.5;
  config.sensor.max_range_m = 90.0;
  config.sensor.self_box = std::array<double, 6>{-1.0, -0.8, -1.5, 2.5, 0.8, 0.2};
  config.sensor.times_from_azimuth = false;
  config.sensor.calibration = "calib.yaml";
  config.sensor.scan_cut_deg = 90.0;
  config.sensor.imu = false;
  config.sensor.imu_topic = "/imu";
  config.sensor.imu_rotation_deg = {1.0, 2.0, 3.0};
  slam::SourceOptions expected;
  expected.meta_path = "meta.json";
  expected.topic = "/points";
  expected.sensor_preset = "vlp16";
  expected.min_range_m = 0.5;
  expected.max_range_m = 90.0;
  expected.self_box = std::array<double, 6>{-1.0, -0.8, -1.5, 2.5, 0.8, 0.2};
  expected.times_from_azimuth = false;
  expected.velodyne_calibration = "calib.yaml";
  expected.scan_cut_deg = 90.0;
  expected.imu = false;
  expected.imu_topic = "/imu";
  expected.imu_rotation_deg = {1.0, 2.0, 3.0};
  expect_same(source_options(config, std::string("meta.json"), std::string("/points")), expected);
}

TEST(MappingSettings, TheDefaultConfigurationGivesTheDefaultLocalizer) {
  const LocalizerSettings configured = localizer_from_config(config::Config{});
  const LocalizerSettings defaults;
  EXPECT_EQ(configured.radius_m, defaults.radius_m);
  EXPECT_EQ(configured.cache_bytes, defaults.cache_bytes);
  EXPECT_EQ(configured.voxel_m, defaults.voxel_m);
  EXPECT_EQ(configured.max_points, defaults.max_points);
  EXPECT_EQ(configured.min_inlier_fraction, defaults.min_inlier_fraction);
  EXPECT_EQ(configured.max_fitness_m, defaults.max_fitness_m);
  EXPECT_EQ(configured.contradiction_fraction, defaults.contradiction_fraction);
  EXPECT_EQ(configured.contradictions, defaults.contradictions);
  EXPECT_EQ(configured.odometry_timeout_s, defaults.odometry_timeout_s);
}

TEST(MappingSettings, TheLocalizeKeysReachTheirSettings) {
  config::Config config;
  config.localize.radius_m = 40.0;
  config.localize.cache_mb = 64.0;
  config.localize.voxel_m = 0.3;
  config.localize.max_points = 5000;
  config.localize.min_inlier_fraction = 0.6;
  config.localize.max_fitness_m = 0.05;
  config.localize.contradiction_fraction = 0.1;
  config.localize.contradictions = 5;
  config.localize.odometry_timeout_s = 20.0;
  const LocalizerSettings s = localizer_from_config(config);
  EXPECT_EQ(s.radius_m, 40.0);
  EXPECT_EQ(s.cache_bytes, size_t{64} << 20);
  EXPECT_EQ(s.voxel_m, 0.3);
  EXPECT_EQ(s.max_points, 5000u);
  EXPECT_EQ(s.min_inlier_fraction, 0.6);
  EXPECT_EQ(s.max_fitness_m, 0.05);
  EXPECT_EQ(s.contradiction_fraction, 0.1);
  EXPECT_EQ(s.contradictions, 5u);
  EXPECT_EQ(s.odometry_timeout_s, 20.0);
}

}  // namespace
}  // namespace featsense::mapping
