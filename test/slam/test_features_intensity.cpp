#include <gtest/gtest.h>

#include <random>

#include "featsense/config/config.hpp"
#include "featsense/slam/features/feature_extractor.hpp"
#include "featsense/slam/features/intensity_edges.hpp"

namespace featsense::slam::features {
namespace {

FeatureSettings defaults() { return from_config(config::Config{}); }

constexpr int kRows = 64;
constexpr int kCols = 256;

/// A valid scan whose intensity channel is value(row, col).
template <typename F>
Scan intensity_scan(F value) {
  Scan scan = Scan::allocate(kRows, kCols);
  ScanChannel& channel = scan.add_channel("intensity");
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      const size_t i = scan.index(r, c);
      scan.valid[i] = 1;
      scan.xyz[i] = Eigen::Vector3f(5.0f, 0.0f, 0.0f);
      scan.range_m[i] = 5.0f;
      channel.values[i] = value(r, c);
    }
  }
  return scan;
}

bool in_square(int r, int c) { return r >= 20 && r < 44 && c >= 100 && c < 160; }

TEST(FeaturesIntensity, BrightSquareHasEdgesOnItsBorderOnly) {
  const Scan scan = intensity_scan([](int r, int c) { return in_square(r, c) ? 200.0f : 10.0f; });
  const auto edges = intensity_edges(scan, defaults());
  ASSERT_TRUE(edges.has_value());
  int border = 0;
  int elsewhere = 0;
  for (int r = 0; r < kRows; ++r) {
    for (int c = 0; c < kCols; ++c) {
      if (!(*edges)[static_cast<size_t>(r) * kCols + c]) continue;
      // Within 2 pixels of the square's outline.
      const bool near_border =
          r >= 18 && r < 46 && c >= 98 && c < 162 && !(r >= 22 && r < 42 && c >= 102 && c < 158);
      (near_border ? border : elsewhere)++;
    }
  }
  EXPECT_EQ(elsewhere, 0);
  EXPECT_GT(border, 2 * (24 + 60));  // most of the outline, both sides of it
  // The square's middle and the background far from it are no edges.
  EXPECT_FALSE(near_edge(*edges, kRows, kCols, 32, 130, 1));
  EXPECT_FALSE(near_edge(*edges, kRows, kCols, 5, 20, 1));
  EXPECT_TRUE(near_edge(*edges, kRows, kCols, 20, 130, 1));
  EXPECT_TRUE(near_edge(*edges, kRows, kCols, 32, 100, 1));
}

TEST(FeaturesIntensity, NoiseAloneGivesFewEdges) {
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(100.0f, 10.0f);
  const Scan scan = intensity_scan([&](int, int) { return noise(rng); });
  const auto edges = intensity_edges(scan, defaults());
  ASSERT_TRUE(edges.has_value());
  size_t count = 0;
  for (uint8_t e : *edges) count += e;
  EXPECT_LT(count, edges->size() / 50) << count;  // under 2 %
}

TEST(FeaturesIntensity, RobustScalingIgnoresOutliersAndInvalidCells) {
  Scan scan = intensity_scan([](int r, int c) { return in_square(r, c) ? 200.0f : 10.0f; });
  scan.channel("intensity")->values[scan.index(0, 0)] = 1e6f;  // one specular return
  scan.invalidate(scan.index(30, 120));                        // a hole inside the square
  const auto grey = intensity_image(scan, defaults());
  ASSERT_TRUE(grey.has_value());
  EXPECT_EQ((*grey)[scan.index(30, 130)], 255);  // the square is bright despite the outlier
  EXPECT_EQ((*grey)[scan.index(5, 5)], 0);
  EXPECT_EQ((*grey)[scan.index(30, 120)], 255);  // the hole takes its row neighbour's value
}

TEST(FeaturesIntensity, NoChannelOrNoValidCellGivesNoImage) {
  Scan bare = Scan::allocate(kRows, kCols);
  EXPECT_FALSE(intensity_edges(bare, defaults()).has_value());
  bare.add_channel("signal");
  EXPECT_FALSE(intensity_edges(bare, defaults()).has_value());  // no valid cell
  EXPECT_FALSE(intensity_edges(Scan{}, defaults()).has_value());
}

TEST(FeaturesIntensity, AChannelOfOneValueIsNoImage) {
  const Scan scan = intensity_scan([](int, int) { return 42.0f; });
  EXPECT_FALSE(intensity_edges(scan, defaults()).has_value());
}

TEST(FeaturesIntensity, ANearlyUniformImageHasNoEdges) {
  // Two grey levels in a checkerboard of single cells: contrast, but no structure wider than
  // the noise the threshold is made for.
  const Scan scan = intensity_scan([](int r, int c) { return 42.0f + 0.5f * ((r + c) % 2); });
  const auto edges = intensity_edges(scan, defaults());
  ASSERT_TRUE(edges.has_value());
  size_t count = 0;
  for (uint8_t e : *edges) count += e;
  EXPECT_LT(count, edges->size() / 20);
}

}  // namespace
}  // namespace featsense::slam::features
