#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "featsense/mesh/compare_to_reference.hpp"
#include "mesh_test_shapes.hpp"

namespace featsense::test {
namespace {

/// float precision at the scale of the shapes (a few metres).
constexpr double kFloatTolerance = 1e-6;

mesh::TriangleMesh cloud(const std::vector<Eigen::Vector3f>& points) {
  mesh::TriangleMesh m;
  m.vertices = points;
  return m;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const mesh::MeshError& e) {
    return e.what();
  }
  return "";
}

TEST(MeshCompare, PointsAboveAndBelowAPlane) {
  const mesh::TriangleMesh plane = grid_plane(-1, 1, -1, 1, 0, 4);
  // 0.25 m above, 0.05 below, 0.15 above, 0.05 below, on the surface: signs follow +z.
  const mesh::TriangleMesh points = cloud({{0.1f, 0.2f, 0.25f},
                                           {-0.3f, 0.7f, -0.05f},
                                           {0.9f, -0.9f, 0.15f},
                                           {0, 0, -0.05f},
                                           {0.5f, 0.5f, 0}});
  mesh::CompareSettings settings;
  settings.thresholds_m = {0.02, 0.06, 0.10};  // none on a distance, where float rounding decides
  const mesh::CompareResult r = mesh::compare_to_reference(points, plane, settings);
  ASSERT_EQ(r.points, 5u);
  EXPECT_TRUE(r.signed_distances);
  const double expected_signed[] = {0.25, -0.05, 0.15, -0.05, 0.0};
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_NEAR(r.signed_distance_m[i], expected_signed[i], kFloatTolerance) << i;
    EXPECT_NEAR(r.unsigned_distance_m[i], std::abs(expected_signed[i]), kFloatTolerance) << i;
  }
  EXPECT_NEAR(r.accuracy.mean_signed, 0.30 / 5, kFloatTolerance);
  EXPECT_NEAR(r.accuracy.mean_abs, 0.50 / 5, kFloatTolerance);
  EXPECT_NEAR(r.accuracy.rmse, std::sqrt((0.0625 + 0.0025 + 0.0225 + 0.0025) / 5), kFloatTolerance);
  EXPECT_NEAR(r.accuracy.median, 0.05, kFloatTolerance);
  EXPECT_NEAR(r.accuracy.p95, 0.25, kFloatTolerance);  // nearest rank ceil(4.75) = 5th
  EXPECT_NEAR(r.accuracy.max, 0.25, kFloatTolerance);
  const double mean = 0.06;
  double var = 0;
  for (double d : expected_signed) var += (d - mean) * (d - mean);
  EXPECT_NEAR(r.accuracy.std_signed, std::sqrt(var / 5), kFloatTolerance);
  // Precision: |d| <= 0.02: 1 of 5; <= 0.06: 3; <= 0.10: 3.
  EXPECT_NEAR(r.scores[0].precision, 0.2, 1e-12);
  EXPECT_NEAR(r.scores[1].precision, 0.6, 1e-12);
  EXPECT_NEAR(r.scores[2].precision, 0.6, 1e-12);
}

TEST(MeshCompare, StatisticsOfManyDistancesAreThoseOfTheSortedDistances) {
  // 200,000 distances spread over six decades (and exact zeros and one far outlier): the
  // figures gathered a distance at a time against those of the sorted list.
  std::mt19937 rng(3);
  std::normal_distribution<double> log_metres(std::log(0.05), 1.5);
  std::bernoulli_distribution below(0.4);
  std::vector<float> signed_m;
  for (int i = 0; i < 200000; ++i) {
    const double d = i % 1000 == 0 ? 0.0 : std::min(std::exp(log_metres(rng)), 50.0);
    signed_m.push_back(static_cast<float>(below(rng) ? -d : d));
  }
  signed_m.push_back(1.0e6f);
  const mesh::DistanceStatistics s = mesh::distance_statistics(signed_m);
  std::vector<double> magnitudes;
  double sum = 0.0, sum_abs = 0.0, sum_squares = 0.0;
  for (const float d : signed_m) {
    magnitudes.push_back(std::abs(static_cast<double>(d)));
    sum += d;
    sum_abs += std::abs(static_cast<double>(d));
    sum_squares += static_cast<double>(d) * d;
  }
  std::sort(magnitudes.begin(), magnitudes.end());
  const double n = static_cast<double>(signed_m.size());
  ASSERT_EQ(s.count, signed_m.size());
  EXPECT_NEAR(s.mean_signed, sum / n, 1e-9);
  EXPECT_NEAR(s.mean_abs, sum_abs / n, 1e-9);
  EXPECT_NEAR(s.rmse, std::sqrt(sum_squares / n), 1e-9);
  double deviations = 0.0;
  for (const float d : signed_m) deviations += (d - sum / n) * (d - sum / n);
  EXPECT_NEAR(s.std_signed, std::sqrt(deviations / n), 1e-6 * s.std_signed);
  const size_t half = signed_m.size() / 2;  // an odd count: the middle one
  EXPECT_NEAR(s.median, magnitudes[half], 3e-5 * magnitudes[half]);
  const size_t rank = static_cast<size_t>(std::ceil(0.95 * n)) - 1;
  EXPECT_NEAR(s.p95, magnitudes[rank], 3e-5 * magnitudes[rank]);
  EXPECT_EQ(s.max, 1.0e6);
  // Where each bin holds one value, the figures are exact.
  const mesh::DistanceStatistics few = mesh::distance_statistics({0.25f, -0.05f, 0.15f, 0.0f});
  EXPECT_EQ(few.median, 0.5 * (static_cast<double>(0.05f) + static_cast<double>(0.15f)));
  EXPECT_EQ(few.p95, static_cast<double>(0.25f));
  EXPECT_EQ(mesh::distance_statistics({}).count, 0u);
}

TEST(MeshCompare, PointsOffABoxInsideOutsideAndBeyondACorner) {
  const mesh::TriangleMesh box = box_mesh(1.0f);
  const mesh::TriangleMesh points = cloud({{1.3f, 0.2f, -0.4f},     // 0.3 outside +x
                                           {0.1f, -0.8f, 0.3f},     // 0.2 inside, nearest -y
                                           {1.3f, 1.4f, 1.2f},      // beyond the corner
                                           {-0.5f, 0.4f, -1.1f}});  // 0.1 below -z
  const mesh::CompareResult r = mesh::compare_to_reference(points, box);
  EXPECT_NEAR(r.signed_distance_m[0], 0.3, kFloatTolerance);
  EXPECT_NEAR(r.signed_distance_m[1], -0.2, kFloatTolerance);
  EXPECT_NEAR(r.signed_distance_m[2], std::sqrt(0.09 + 0.16 + 0.04), kFloatTolerance);
  EXPECT_NEAR(r.signed_distance_m[3], 0.1, kFloatTolerance);
}

TEST(MeshCompare, SphereAlongFaceNormals) {
  // Points on the normals through triangle centroids of an icosphere: the nearest point of the
  // (convex) mesh is the centroid, so the distance is the offset exactly.
  const mesh::TriangleMesh sphere = icosphere(2.0f, 3);
  std::vector<Eigen::Vector3f> points;
  std::vector<double> expected;
  for (size_t t = 0; t < sphere.triangles.size(); t += 7) {
    const Eigen::Vector3i& tri = sphere.triangles[t];
    const Eigen::Vector3d a = sphere.vertices[static_cast<size_t>(tri[0])].cast<double>();
    const Eigen::Vector3d b = sphere.vertices[static_cast<size_t>(tri[1])].cast<double>();
    const Eigen::Vector3d c = sphere.vertices[static_cast<size_t>(tri[2])].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
    const double offset = (t % 2 == 0 ? 0.04 : -0.01) * (1.0 + static_cast<double>(t % 5));
    points.push_back(((a + b + c) / 3.0 + offset * n).cast<float>());
    expected.push_back(offset);
  }
  const mesh::CompareResult r = mesh::compare_to_reference(cloud(points), sphere);
  double sum = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(r.signed_distance_m[i], expected[i], kFloatTolerance) << i;
    sum += expected[i];
  }
  EXPECT_NEAR(r.accuracy.mean_signed, sum / static_cast<double>(points.size()), kFloatTolerance);
}

TEST(MeshCompare, CompletenessOfHalfAPlane) {
  // The estimate covers x in [-1, 0] of the 2 x 2 m reference: reference samples within t of it
  // cover x <= t, a share of (1 + t) / 2. Sampling at 10^4 per m^2 (40,000 samples) leaves a
  // binomial standard deviation of 0.0025; 0.01 is four of them.
  const mesh::TriangleMesh reference = grid_plane(-1, 1, -1, 1, 0, 10);
  const mesh::TriangleMesh estimate = grid_plane(-1, 0, -1, 1, 0, 5);
  const mesh::CompareResult r = mesh::compare_to_reference(estimate, reference);
  EXPECT_NEAR(static_cast<double>(r.reference_samples), 40000, 4 * 200);
  ASSERT_EQ(r.scores.size(), 3u);
  for (const mesh::ThresholdScores& s : r.scores) {
    const double completeness = 0.5 * (1.0 + s.threshold_m);
    EXPECT_NEAR(s.completeness, completeness, 0.01) << s.threshold_m;
    EXPECT_DOUBLE_EQ(s.precision, 1.0);
    EXPECT_NEAR(s.fscore, 2 * completeness / (1 + completeness), 0.01);
  }
  EXPECT_NEAR(r.accuracy.max, 0.0, kFloatTolerance);
  // Same seed, same samples.
  EXPECT_EQ(mesh::compare_to_reference(estimate, reference).scores[0].completeness,
            r.scores[0].completeness);
}

TEST(MeshCompare, PointCloudReferenceSignedOnlyWithNormals) {
  mesh::TriangleMesh reference = cloud({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const mesh::TriangleMesh points = cloud({{0, 0, -0.3f}, {1.0f, 0.4f, 0}});
  const mesh::CompareResult unsigned_result = mesh::compare_to_reference(points, reference);
  EXPECT_FALSE(unsigned_result.signed_distances);
  EXPECT_FALSE(unsigned_result.reference_is_mesh);
  EXPECT_NEAR(unsigned_result.signed_distance_m[0], 0.3, kFloatTolerance);
  EXPECT_NEAR(unsigned_result.signed_distance_m[1], 0.4, kFloatTolerance);
  EXPECT_EQ(unsigned_result.reference_samples, 3u);
  reference.normals = {{0, 0, 1}, {0, 1, 0}, {0, 0, 1}};
  const mesh::CompareResult signed_result = mesh::compare_to_reference(points, reference);
  EXPECT_TRUE(signed_result.signed_distances);
  EXPECT_NEAR(signed_result.signed_distance_m[0], -0.3, kFloatTolerance);
  EXPECT_NEAR(signed_result.signed_distance_m[1], 0.4, kFloatTolerance);
}

TEST(MeshCompare, MaxDistLeavesFarPointsOutOfAccuracy) {
  const mesh::TriangleMesh plane = grid_plane(-1, 1, -1, 1, 0, 2);
  const mesh::TriangleMesh points = cloud({{0, 0, 0.1f}, {0, 0, -0.2f}, {0, 0, 5.0f}});
  mesh::CompareSettings settings;
  settings.max_dist_m = 1.0;
  const mesh::CompareResult r = mesh::compare_to_reference(points, plane, settings);
  EXPECT_EQ(r.beyond_max_dist, 1u);
  EXPECT_EQ(r.accuracy.count, 2u);
  EXPECT_NEAR(r.accuracy.max, 0.2, kFloatTolerance);
  EXPECT_NEAR(r.accuracy.mean_signed, -0.05, kFloatTolerance);
  ASSERT_EQ(r.histogram_counts.size(), 20u);
  EXPECT_EQ(r.histogram_counts[2], 1u);  // 0.1 m in [0.1, 0.15)
  EXPECT_EQ(r.histogram_counts[4], 1u);  // 0.2 m in [0.2, 0.25)
}

TEST(MeshCompare, EmptyAndDegenerateInputsAreErrors) {
  const mesh::TriangleMesh plane = grid_plane(-1, 1, -1, 1, 0, 2);
  EXPECT_NE(error_of([&] {
              mesh::compare_to_reference(mesh::TriangleMesh{}, plane);
            }).find("the estimate has no vertices"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              mesh::compare_to_reference(plane, mesh::TriangleMesh{});
            }).find("the reference has no vertices"),
            std::string::npos);
  mesh::TriangleMesh flat;
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}};
  EXPECT_NE(error_of([&] { mesh::compare_to_reference(plane, flat); }).find("degenerate"),
            std::string::npos);
  mesh::TriangleMesh nan_point = plane;
  nan_point.vertices[3].y() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(error_of([&] {
              mesh::compare_to_reference(nan_point, plane);
            }).find("the estimate: vertex 3 has a non-finite coordinate"),
            std::string::npos);
  mesh::TriangleMesh broken = plane;
  broken.triangles.emplace_back(0, 1, 99);
  EXPECT_NE(
      error_of([&] { mesh::compare_to_reference(plane, broken); }).find("refers to vertex 99"),
      std::string::npos);
}

}  // namespace
}  // namespace featsense::test
