#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "featsense/config/config.hpp"
#include "featsense/slam/features/feature_extractor.hpp"

namespace featsense::slam::features {
namespace {

FeatureSettings defaults() { return from_config(config::Config{}); }

// A box room around the sensor (at the origin): x in [-6, 5], y in [-3.5, 4.5],
// z in [-1.5, 2.5]; each face has its own reflectivity.
constexpr float kLow[3] = {-6.0f, -3.5f, -1.5f};
constexpr float kHigh[3] = {5.0f, 4.5f, 2.5f};

/// A spinning sensor of rows beams over +/- fov_deg, cols columns, clockwise from +x.
Scan box_room_scan(int rows, int cols, double fov_deg, bool with_intensity = true,
                   bool uniform_intensity = false) {
  Scan scan = Scan::allocate(rows, cols);
  ScanChannel* reflectivity = with_intensity ? &scan.add_channel("reflectivity") : nullptr;
  for (int r = 0; r < rows; ++r) {
    const double elevation = (fov_deg - 2.0 * fov_deg * r / (rows - 1)) * M_PI / 180.0;
    for (int c = 0; c < cols; ++c) {
      const double azimuth = -2.0 * M_PI * c / cols;
      const Eigen::Vector3d d(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
      double t = std::numeric_limits<double>::infinity();
      int face = 0;
      for (int k = 0; k < 3; ++k) {
        if (std::abs(d[k]) < 1e-12) continue;
        const double tk = (d[k] > 0 ? kHigh[k] : kLow[k]) / d[k];
        if (tk < t) {
          t = tk;
          face = 2 * k + (d[k] > 0);
        }
      }
      const size_t i = scan.index(r, c);
      scan.xyz[i] = (t * d).cast<float>();
      scan.range_m[i] = static_cast<float>(t);
      scan.valid[i] = 1;
      scan.time_offset_s[i] = 0.1f * static_cast<float>(c) / static_cast<float>(cols);
      if (reflectivity) reflectivity->values[i] = uniform_intensity ? 50.0f : 20.0f + 30.0f * face;
    }
  }
  return scan;
}

/// How many of the point's coordinates lie within tol of a face of the room.
int faces_near(const Eigen::Vector3f& p, float tol) {
  int n = 0;
  for (int k = 0; k < 3; ++k)
    n += std::abs(p[k] - kLow[k]) < tol || std::abs(p[k] - kHigh[k]) < tol;
  return n;
}

void expect_box_room_features(int rows, int cols, double fov_deg) {
  const Scan scan = box_room_scan(rows, cols, fov_deg);
  FeatureStats stats;
  const FeatureSet set = extract_features(scan, defaults(), &stats);
  SCOPED_TRACE(std::to_string(rows) + " x " + std::to_string(cols));
  EXPECT_TRUE(set.intensity_confirmed);
  ASSERT_GT(set.edges.size(), 0u);
  ASSERT_GT(set.surfaces.size(), static_cast<size_t>(rows * 6));  // surfaces in every sector
  EXPECT_EQ(set.edge_time_s.size(), set.edges.size());
  EXPECT_EQ(set.surface_time_s.size(), set.surfaces.size());
  // Edges lie on the room's edges (two faces within two column spacings at 8 m).
  const float spacing = static_cast<float>(2.0 * M_PI / cols * 8.0);
  for (const auto& p : set.edges) EXPECT_GE(faces_near(p, 2.0f * spacing), 2) << p.transpose();
  // Every vertical corner is found.
  for (float x : {kLow[0], kHigh[0]}) {
    for (float y : {kLow[1], kHigh[1]}) {
      const bool found = std::any_of(set.edges.begin(), set.edges.end(), [&](const auto& p) {
        return std::hypot(p.x() - x, p.y() - y) < 2.0f * spacing;
      });
      EXPECT_TRUE(found) << "corner " << x << ", " << y;
    }
  }
  // Surfaces lie on a face, and none where a scan line crosses a vertical corner.
  for (const auto& p : set.surfaces) {
    EXPECT_GE(faces_near(p, 1e-3f), 1) << p.transpose();
    for (float x : {kLow[0], kHigh[0]}) {
      for (float y : {kLow[1], kHigh[1]}) {
        EXPECT_GT(std::hypot(p.x() - x, p.y() - y), 2.0f * spacing) << p.transpose();
      }
    }
  }
  EXPECT_EQ(stats.edges, set.edges.size());
  EXPECT_LE(stats.edges, stats.edges_geometric);
}

TEST(FeaturesScans, BoxRoomVlp16) { expect_box_room_features(16, 360, 15.0); }

TEST(FeaturesScans, BoxRoomOs1_128) { expect_box_room_features(128, 1024, 22.5); }

TEST(FeaturesScans, FusionOnOffAndWithoutIntensity) {
  FeatureSettings on = defaults();
  on.intensity_fusion = true;
  FeatureSettings off = on;
  off.intensity_fusion = false;

  // Each face its own reflectivity: the corners are intensity edges, the fusion keeps them.
  const Scan faces = box_room_scan(16, 360, 15.0);
  FeatureStats stats_on;
  const FeatureSet with = extract_features(faces, on, &stats_on);
  const FeatureSet without = extract_features(faces, off);
  EXPECT_TRUE(with.intensity_confirmed);
  EXPECT_FALSE(without.intensity_confirmed);
  EXPECT_EQ(without.edges.size(), stats_on.edges_geometric);
  EXPECT_GE(with.edges.size() * 10, without.edges.size() * 8);
  EXPECT_EQ(with.surfaces.size(), without.surfaces.size());

  // One reflectivity value throughout tells nothing: the fusion is off for that scan (rather
  // than dropping every edge).
  const Scan uniform = box_room_scan(16, 360, 15.0, true, true);
  const FeatureSet flat = extract_features(uniform, on);
  EXPECT_FALSE(flat.intensity_confirmed);
  EXPECT_EQ(flat.edges.size(), without.edges.size());

  // No intensity channel: the fusion is off, whatever the setting.
  const Scan bare = box_room_scan(16, 360, 15.0, false);
  const FeatureSet plain = extract_features(bare, on);
  EXPECT_FALSE(plain.intensity_confirmed);
  EXPECT_EQ(plain.edges.size(), without.edges.size());
}

TEST(FeaturesScans, EmptyAndInvalidScansGiveNoFeatures) {
  const FeatureSettings s = defaults();
  EXPECT_EQ(extract_features(Scan{}, s).size(), 0u);
  EXPECT_EQ(extract_features(Scan::allocate(16, 360), s).size(), 0u);
  EXPECT_EQ(extract_features(Scan::allocate(0, 1024), s).size(), 0u);
  EXPECT_EQ(extract_features(Scan::allocate(128, 3), s).size(), 0u);  // lines too short

  Scan nan = box_room_scan(16, 360, 15.0);
  for (size_t i = 0; i < nan.size(); ++i) nan.invalidate(i);
  EXPECT_EQ(extract_features(nan, s).size(), 0u);

  Scan broken = box_room_scan(16, 360, 15.0);
  broken.range_m.resize(5);  // inconsistent sizes: nothing, no crash
  EXPECT_EQ(extract_features(broken, s).size(), 0u);

  // NaN intensities and every other cell invalid: no crash, only valid points as features.
  Scan holes = box_room_scan(16, 360, 15.0);
  for (auto& v : holes.channel("reflectivity")->values) v = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < holes.size(); i += 2) holes.invalidate(i);
  const FeatureSet set = extract_features(holes, s);
  EXPECT_EQ(set.size(), 0u);  // no 11 contiguous valid points anywhere
}

TEST(FeaturesScans, SpeedOfAnOs1_128Scan) {
  Scan scan = box_room_scan(128, 1024, 22.5);
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  for (size_t i = 0; i < scan.size(); ++i) {
    scan.xyz[i] += Eigen::Vector3f(noise(rng), noise(rng), noise(rng));
    scan.range_m[i] = scan.xyz[i].norm();
  }
  const FeatureSettings s = defaults();
  std::vector<double> ms;
  FeatureStats stats;
  for (int k = 0; k < 15; ++k) {
    const auto start = std::chrono::steady_clock::now();
    const FeatureSet set = extract_features(scan, s, &stats);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
    EXPECT_GT(set.size(), 0u);
  }
  std::sort(ms.begin(), ms.end());
  std::printf(
      "extract_features 128 x 1024: median %.2f ms (curvature+filters %.2f, selection %.2f, "
      "intensity+fusion %.2f); %zu edges (%zu geometric), %zu surfaces\n",
      ms[ms.size() / 2], stats.curvature_ms, stats.selection_ms, stats.intensity_ms, stats.edges,
      stats.edges_geometric, stats.surfaces);
  EXPECT_LT(ms[ms.size() / 2], 200.0);  // a sanity bound only; the figure is printed
}

}  // namespace
}  // namespace featsense::slam::features
