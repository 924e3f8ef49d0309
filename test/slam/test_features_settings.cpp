// One home per default: the feature extraction's settings as the default configuration gives
// them (config.hpp, default.yaml) are the settings' own defaults, and every key reaches its
// field.

#include <gtest/gtest.h>

#include "featsense/slam/features/feature_extractor.hpp"

namespace featsense::slam::features {
namespace {

void expect_same(const FeatureSettings& a, const FeatureSettings& b) {
  EXPECT_EQ(a.neighbours, b.neighbours);
  EXPECT_EQ(a.sectors, b.sectors);
  EXPECT_EQ(a.max_edges_per_sector, b.max_edges_per_sector);
  EXPECT_EQ(a.max_surfaces_per_sector, b.max_surfaces_per_sector);
  EXPECT_EQ(a.edge_threshold, b.edge_threshold);
  EXPECT_EQ(a.max_edge_threshold, b.max_edge_threshold);
  EXPECT_EQ(a.surface_threshold, b.surface_threshold);
  EXPECT_EQ(a.min_range_m, b.min_range_m);
  EXPECT_EQ(a.max_range_m, b.max_range_m);
  EXPECT_EQ(a.occlusion_jump_m, b.occlusion_jump_m);
  EXPECT_EQ(a.parallel_gap_ratio, b.parallel_gap_ratio);
  EXPECT_EQ(a.intensity_fusion, b.intensity_fusion);
  EXPECT_EQ(a.intensity_percentile, b.intensity_percentile);
  EXPECT_EQ(a.intensity_blur_sigma, b.intensity_blur_sigma);
  EXPECT_EQ(a.intensity_bilateral_sigma_color, b.intensity_bilateral_sigma_color);
  EXPECT_EQ(a.intensity_bilateral_sigma_space, b.intensity_bilateral_sigma_space);
  EXPECT_EQ(a.intensity_edge_fraction, b.intensity_edge_fraction);
  EXPECT_EQ(a.intensity_noise_factor, b.intensity_noise_factor);
  EXPECT_EQ(a.intensity_tolerance_px, b.intensity_tolerance_px);
}

TEST(FeatureSettings, TheDefaultConfigurationGivesTheDefaults) {
  expect_same(from_config(config::Config{}), FeatureSettings{});
}

TEST(FeatureSettings, EveryKeyReachesItsSetting) {
  config::Config config;
  config::FeaturesConfig& f = config.features;
  f.neighbours = 7;
  f.sectors = 9;
  f.max_edges_per_sector = 11;
  f.max_surfaces_per_sector = 13;
  f.edge_threshold = 0.15;
  f.max_edge_threshold = 0.85;
  f.surface_threshold = 0.03;
  f.min_range_m = 1.5;
  f.max_range_m = 70.0;
  f.occlusion_jump_m = 0.4;
  f.parallel_gap_ratio = 6.0;
  f.intensity_percentile = 2.0;
  f.intensity_blur_sigma = 0.7;
  f.intensity_bilateral_sigma_color = 25.0;
  f.intensity_bilateral_sigma_space = 3.0;
  f.intensity_edge_fraction = 0.3;
  f.intensity_noise_factor = 4.0;
  f.intensity_tolerance_px = 2;
  config.odometry.intensity_fusion = false;

  FeatureSettings expected;
  expected.neighbours = 7;
  expected.sectors = 9;
  expected.max_edges_per_sector = 11;
  expected.max_surfaces_per_sector = 13;
  expected.edge_threshold = 0.15;
  expected.max_edge_threshold = 0.85;
  expected.surface_threshold = 0.03;
  expected.min_range_m = 1.5;
  expected.max_range_m = 70.0;
  expected.occlusion_jump_m = 0.4;
  expected.parallel_gap_ratio = 6.0;
  expected.intensity_fusion = false;
  expected.intensity_percentile = 2.0;
  expected.intensity_blur_sigma = 0.7;
  expected.intensity_bilateral_sigma_color = 25.0;
  expected.intensity_bilateral_sigma_space = 3.0;
  expected.intensity_edge_fraction = 0.3;
  expected.intensity_noise_factor = 4.0;
  expected.intensity_tolerance_px = 2;
  expect_same(from_config(config), expected);
}

}  // namespace
}  // namespace featsense::slam::features
