#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "featsense/config/config.hpp"
#include "featsense/slam/features/curvature.hpp"
#include "featsense/slam/features/feature_extractor.hpp"
#include "featsense/slam/features/feature_filters.hpp"
#include "featsense/slam/features/feature_selection.hpp"

namespace featsense::slam::features {
namespace {

FeatureSettings defaults() { return from_config(config::Config{}); }

/// A scan of one or more rows whose cell (row, col) holds point(row, col).
Scan line_scan(int rows, int cols, const std::function<Eigen::Vector3f(int, int)>& point) {
  Scan scan = Scan::allocate(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const size_t i = scan.index(r, c);
      scan.xyz[i] = point(r, c);
      scan.range_m[i] = scan.xyz[i].norm();
      scan.valid[i] = 1;
    }
  }
  return scan;
}

TEST(FeaturesCurvature, StraightLineIsZero) {
  const Scan scan =
      line_scan(1, 40, [](int, int c) { return Eigen::Vector3f(5.0f, 0.1f * c, 1.0f); });
  for (int col = 5; col < 35; ++col) {
    EXPECT_NEAR(raw_curvature(scan, 0, col, 5), 0.0f, 1e-8f) << col;
    EXPECT_NEAR(normalised_curvature(scan, 0, col, 5), 0.0f, 1e-6f) << col;
  }
  EXPECT_TRUE(std::isnan(raw_curvature(scan, 0, 4, 5)));  // neighbourhood leaves the line
  EXPECT_TRUE(std::isnan(raw_curvature(scan, 0, 35, 5)));
}

TEST(FeaturesCurvature, RightAngleCornerHasEquationOnesValue) {
  // Legs along x and y meeting at col 10, spacing d: sum_j (P_j - P_i) = d * N(N+1)/2 * (1, 1).
  const float d = 0.1f;
  const Scan scan = line_scan(1, 21, [&](int, int c) {
    const Eigen::Vector3f corner(5.0f, 5.0f, 0.0f);
    return c <= 10 ? Eigen::Vector3f(corner + Eigen::Vector3f(d * (10 - c), 0, 0))
                   : Eigen::Vector3f(corner + Eigen::Vector3f(0, d * (c - 10), 0));
  });
  const int n = 5;
  const float leg = d * n * (n + 1) / 2.0f;
  EXPECT_NEAR(raw_curvature(scan, 0, 10, n), 2.0f * leg * leg, 1e-5f);
  EXPECT_NEAR(normalised_curvature(scan, 0, 10, n), 0.5f, 1e-5f);  // cos^2(45 deg)
  // One cell off the corner the value is smaller but non-zero.
  EXPECT_GT(raw_curvature(scan, 0, 10, n), raw_curvature(scan, 0, 9, n));
  EXPECT_GT(raw_curvature(scan, 0, 9, n), 0.0f);
}

TEST(FeaturesCurvature, NormalisedValueIsTheSameAtAnyRangeAndSpacing) {
  for (float d : {0.01f, 0.1f, 0.5f}) {
    const Scan scan = line_scan(1, 21, [&](int, int c) {
      return c <= 10 ? Eigen::Vector3f(40.0f + d * (10 - c), 0, 0)
                     : Eigen::Vector3f(40.0f, d * (c - 10), 0);
    });
    EXPECT_NEAR(normalised_curvature(scan, 0, 10, 5), 0.5f, 1e-4f) << d;
  }
}

TEST(FeaturesCurvature, InvalidCellBreaksTheNeighbourhood) {
  Scan scan = line_scan(1, 40, [](int, int c) { return Eigen::Vector3f(5.0f, 0.1f * c, 0.0f); });
  scan.invalidate(scan.index(0, 20));
  for (int col = 15; col <= 25; ++col) EXPECT_TRUE(std::isnan(raw_curvature(scan, 0, col, 5)));
  EXPECT_FALSE(std::isnan(raw_curvature(scan, 0, 14, 5)));
  EXPECT_FALSE(std::isnan(raw_curvature(scan, 0, 26, 5)));
}

TEST(FeaturesSelection, LimitsPerSectorAndNeighbourExclusion) {
  FeatureSettings s = defaults();
  s.sectors = 2;
  s.max_edges_per_sector = 3;
  s.max_surfaces_per_sector = 4;
  const int cols = 210;
  std::vector<float> curvature(cols, 0.0f);
  for (int c = 0; c < s.neighbours; ++c) curvature[c] = curvature[cols - 1 - c] = NAN;
  // Every column an edge candidate of falling curvature: picks must be >= N + 1 apart.
  for (int c = 5; c < 105; ++c) curvature[c] = 0.5f - 0.001f * c;
  const std::vector<uint8_t> excluded(cols, 0);
  const LinePicks picks = select_line_features(curvature.data(), excluded.data(), cols, s);
  ASSERT_EQ(picks.edges.size(), 3u);  // the first sector's limit; the second has no candidates
  EXPECT_EQ(picks.edges[0], 5);
  for (size_t k = 1; k < picks.edges.size(); ++k) {
    EXPECT_GT(picks.edges[k] - picks.edges[k - 1], s.neighbours);
  }
  // Surfaces: zero curvature in the second sector, at most 4 there, spread out too.
  int second = 0;
  for (int col : picks.surfaces) {
    if (col >= 105) ++second;
  }
  EXPECT_EQ(second, 4);
  std::vector<int> all = picks.edges;
  all.insert(all.end(), picks.surfaces.begin(), picks.surfaces.end());
  for (size_t a = 0; a < all.size(); ++a) {
    for (size_t b = a + 1; b < all.size(); ++b) EXPECT_GT(std::abs(all[a] - all[b]), s.neighbours);
  }
  // Above the maximum: no edge; excluded cells: nothing.
  std::vector<float> spiky(cols, 0.95f);
  for (int c = 0; c < s.neighbours; ++c) spiky[c] = spiky[cols - 1 - c] = NAN;
  EXPECT_TRUE(select_line_features(spiky.data(), excluded.data(), cols, s).edges.empty());
  const std::vector<uint8_t> all_excluded(cols, 1);
  const LinePicks none = select_line_features(curvature.data(), all_excluded.data(), cols, s);
  EXPECT_TRUE(none.edges.empty());
  EXPECT_TRUE(none.surfaces.empty());
}

TEST(FeaturesFilters, SurfaceParallelToTheBeamIsExcluded) {
  FeatureSettings s = defaults();
  s.occlusion_jump_m = 100.0;  // the range grows fast along the wall: test this filter alone
  const int cols = 360;
  // A wall at x = 5 seen across 60 columns: near the beam's foot (col 0) the gaps are about
  // one column spacing; at grazing columns (incidence > 80 deg) they are many.
  const Scan scan = line_scan(1, cols, [&](int, int c) {
    const double a = 2.0 * M_PI * c / cols;
    const double angle = std::min(a, 1.45);  // beyond that the points crowd at the far end
    return Eigen::Vector3f(5.0f, static_cast<float>(5.0 * std::tan(angle)) + 0.001f * c, 0.0f);
  });
  const std::vector<uint8_t> excluded = excluded_cells(scan, s);
  EXPECT_EQ(excluded[10], 0);  // 10 deg incidence, 9 m range: fine
  EXPECT_EQ(excluded[45], 0);  // 45 deg
  EXPECT_EQ(excluded[82], 1);  // 82 deg: gaps 7 times the column spacing
}

TEST(FeaturesFilters, FarSideOfAnOcclusionIsExcluded) {
  const FeatureSettings s = defaults();
  // A wall at 10 m with a pole at 5 m covering columns 30..39.
  const Scan scan = line_scan(1, 80, [](int, int c) {
    const float x = (c >= 30 && c < 40) ? 5.0f : 10.0f;
    return Eigen::Vector3f(x, x * 0.005f * (c - 40), 0.0f);
  });
  const std::vector<uint8_t> excluded = excluded_cells(scan, s);
  for (int c = 24; c <= 29; ++c) EXPECT_EQ(excluded[c], 1) << c;  // far side, left
  for (int c = 40; c <= 45; ++c) EXPECT_EQ(excluded[c], 1) << c;  // far side, right
  // The pole's cells within N of its ends count the wall in their curvature: none is a
  // feature by its curvature (its ends are edges as occluding boundaries).
  for (int c = 30; c < 40; ++c) EXPECT_EQ(excluded[c], 1) << c;
  EXPECT_EQ(excluded[15], 0);
  EXPECT_EQ(excluded[60], 0);
  // Range limits.
  FeatureSettings near = s;
  near.max_range_m = 8.0;
  EXPECT_EQ(excluded_cells(scan, near)[60], 1);
  EXPECT_EQ(excluded_cells(scan, near)[15], 1);
}

/// One row of columns 2 pi / 1024 apart (an OS1-128's), azimuth 0 at column 40: a face on the
/// plane x = 5 m from y = face_from to y = face_to, a wall at x = 10 m behind it.
Scan face_before_wall(float face_from, float face_to) {
  const double step = 2.0 * M_PI / 1024.0;
  return line_scan(1, 120, [&](int, int c) {
    const double azimuth = step * (c - 40);
    const Eigen::Vector3d direction(std::cos(azimuth), std::sin(azimuth), 0.0);
    const double y_on_face = 5.0 * std::tan(azimuth);
    const double x = (y_on_face >= face_from && y_on_face <= face_to) ? 5.0 : 10.0;
    return Eigen::Vector3f((x / direction.x() * direction).cast<float>());
  });
}

TEST(FeaturesFilters, OcclusionBoundariesAreTheNearCellsOfAFaceThatEnds) {
  const FeatureSettings s = defaults();
  const Scan scan = face_before_wall(0.2f, 0.8f);  // columns 47..65 on the face
  const std::vector<int8_t> side = occluding_boundaries(scan, s);
  for (int c = 0; c < scan.cols; ++c) {
    const int expected = c == 47 ? -1 : (c == 65 ? 1 : 0);
    EXPECT_EQ(side[static_cast<size_t>(c)], expected) << c;
  }
  // A face narrower than the N cells behind a boundary (a wire, a leaf) has none.
  const std::vector<int8_t> thin = occluding_boundaries(face_before_wall(0.2f, 0.22f), s);
  for (int8_t v : thin) EXPECT_EQ(v, 0);
  // Nor one out of the range limits.
  FeatureSettings near = s;
  near.max_range_m = 4.0;
  for (int8_t v : occluding_boundaries(scan, near)) EXPECT_EQ(v, 0);
  // A range that is not a number (a reader's bad cell marked valid) makes no jump: the face's
  // end beside it is no boundary, nor is one whose face behind holds it.
  Scan bad = scan;
  bad.range_m[66] = std::numeric_limits<float>::quiet_NaN();
  bad.range_m[50] = std::numeric_limits<float>::quiet_NaN();
  const std::vector<int8_t> with_nan = occluding_boundaries(bad, s);
  EXPECT_EQ(with_nan[65], 0);
  EXPECT_EQ(with_nan[47], 0);  // its N cells behind reach column 52
}

TEST(FeaturesFilters, BoundaryPointFindsTheFacesEndWithoutBias) {
  // The face's true end swept over one column's spacing: the near cell falls short of it by
  // half a spacing on average, the boundary point by nothing.
  const FeatureSettings s = defaults();
  // Where the rays of columns 65 and 66 meet the face: about 3.1 cm apart.
  const double step = 2.0 * M_PI / 1024.0;
  const float last_ray = static_cast<float>(5.0 * std::tan(step * 25));
  const float spacing = static_cast<float>(5.0 * std::tan(step * 26)) - last_ray;
  double near_cell_mean = 0.0;
  double boundary_mean = 0.0;
  double boundary_worst = 0.0;
  const int phases = 64;
  for (int k = 0; k < phases; ++k) {
    const float end = last_ray + spacing * (static_cast<float>(k) + 0.5f) / phases;
    const Scan scan = face_before_wall(0.2f, end);
    const std::vector<int8_t> side = occluding_boundaries(scan, s);
    int at = -1;
    for (int c = 0; c < scan.cols; ++c) {
      if (side[static_cast<size_t>(c)] == 1) at = c;
    }
    ASSERT_EQ(at, 65) << k;
    const Eigen::Vector3f p = boundary_point(scan, 0, at, 1, s.neighbours);
    EXPECT_NEAR(p.x(), 5.0f, 1e-4f);  // on the face
    near_cell_mean += (scan.xyz[static_cast<size_t>(at)].y() - end) / phases;
    boundary_mean += (p.y() - end) / phases;
    boundary_worst = std::max(boundary_worst, std::abs(static_cast<double>(p.y() - end)));
  }
  EXPECT_NEAR(near_cell_mean, -0.5 * spacing, 0.02 * spacing);
  EXPECT_NEAR(boundary_mean, 0.0, 0.02 * spacing);
  EXPECT_LE(boundary_worst, 0.51 * spacing);
}

TEST(FeaturesFilters, ExtractedEdgeOfAnOcclusionIsItsBoundaryPoint) {
  FeatureSettings s = defaults();
  s.intensity_fusion = false;
  const Scan scan = face_before_wall(0.2f, 0.8f);
  const FeatureSet set = extract_features(scan, s);
  const Eigen::Vector3f left = boundary_point(scan, 0, 47, -1, s.neighbours);
  const Eigen::Vector3f right = boundary_point(scan, 0, 65, 1, s.neighbours);
  bool found_left = false;
  bool found_right = false;
  for (const Eigen::Vector3f& e : set.edges) {
    found_left |= (e - left).norm() < 1e-5f;
    found_right |= (e - right).norm() < 1e-5f;
    // Nothing inside the face's ends, where the curvature measured the wall behind.
    if (std::abs(e.x() - 5.0f) < 0.01f) {
      EXPECT_TRUE((e - left).norm() < 1e-5f || (e - right).norm() < 1e-5f) << e.transpose();
    }
  }
  EXPECT_TRUE(found_left);
  EXPECT_TRUE(found_right);
}

}  // namespace
}  // namespace featsense::slam::features
