#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "featsense/mesh/compare_to_reference.hpp"
#include "featsense/mesh/region_comparison.hpp"
#include "featsense/mesh/surface_regions.hpp"
#include "featsense/mesh/tiled_point_file.hpp"
#include "mesh_test_shapes.hpp"

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

mesh::TriangleMesh moved(mesh::TriangleMesh m, const Eigen::Vector3f& by) {
  for (Eigen::Vector3f& v : m.vertices) v += by;
  return m;
}

/// A street of 40 x 40 m: the ground and balls standing on it (seen from every side).
mesh::TriangleMesh street() {
  mesh::TriangleMesh m = grid_plane(-20, 20, -20, 20, 0, 60);
  for (const Eigen::Vector3f& at : {Eigen::Vector3f(-12, -3, 2), Eigen::Vector3f(5, 9, 3),
                                    Eigen::Vector3f(14, -15, 1.5f), Eigen::Vector3f(0, 0, 2.5f)}) {
    m.append(moved(icosphere(at.z(), 3), at));
  }
  return m;
}

/// The street as a map would have it: vertices off by a few centimetres, one ball missing, a
/// wall that is not in the truth (3 to 9 m from it) and a patch beyond the truth's edge.
mesh::TriangleMesh estimate_of(const mesh::TriangleMesh& truth) {
  mesh::TriangleMesh m = truth;
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  for (Eigen::Vector3f& v : m.vertices) v += Eigen::Vector3f(noise(rng), noise(rng), noise(rng));
  // Drop the last ball's triangles (its vertices stay, unreferenced, as in a cleaned mesh).
  m.triangles.resize(m.triangles.size() - icosphere(1, 3).triangles.size());
  mesh::TriangleMesh wall = grid_plane(-3, 3, 0, 6, 0, 12);
  for (Eigen::Vector3f& v : wall.vertices) v = Eigen::Vector3f(8.0f, v.x() - 10.0f, v.y() + 3.0f);
  m.append(wall);
  m.append(grid_plane(21, 26, -2, 2, 0.5f, 5));
  return m;
}

mesh::CompareSettings settings() {
  mesh::CompareSettings s;
  s.samples_per_m2 = 400.0;
  return s;
}

mesh::RegionComparisonSettings small_regions() {
  mesh::RegionComparisonSettings r;
  r.region_size_m = 7.0;
  r.margin_m = 0.5;  // the wall and the patch beyond it are settled at the end
  return r;
}

void expect_same_accuracy(const mesh::CompareResult& whole, const mesh::CompareResult& regions) {
  ASSERT_EQ(regions.unsigned_distance_m.size(), whole.unsigned_distance_m.size());
  for (size_t i = 0; i < whole.unsigned_distance_m.size(); ++i) {
    ASSERT_NEAR(regions.unsigned_distance_m[i], whole.unsigned_distance_m[i], 1e-6) << i;
    ASSERT_NEAR(regions.signed_distance_m[i], whole.signed_distance_m[i], 1e-6) << i;
  }
  EXPECT_NEAR(regions.accuracy.mean_abs, whole.accuracy.mean_abs, 1e-9);
  EXPECT_NEAR(regions.accuracy.p95, whole.accuracy.p95, 1e-6);
  EXPECT_NEAR(regions.accuracy.max, whole.accuracy.max, 1e-6);
  EXPECT_EQ(regions.accuracy.count, whole.accuracy.count);
  EXPECT_EQ(regions.histogram_counts, whole.histogram_counts);
  for (size_t k = 0; k < whole.scores.size(); ++k) {
    EXPECT_DOUBLE_EQ(regions.scores[k].precision, whole.scores[k].precision);
  }
}

TEST(RegionComparison, AgainstAMeshEqualsTheWholeComparison) {
  const mesh::TriangleMesh truth = street();
  const mesh::TriangleMesh estimate = estimate_of(truth);
  const mesh::CompareResult whole = mesh::compare_to_reference(estimate, truth, settings());
  // The wall is 3 to 9 m from the truth: beyond the margin of 0.5 m.
  ASSERT_GT(whole.accuracy.max, 3.0);
  size_t settled = 0;
  mesh::RegionComparisonSettings regions = small_regions();
  regions.progress = [&](size_t done, size_t total) { settled = total - done; };
  const mesh::CompareResult by_region = mesh::compare_by_region(
      mesh::MeshRegions(estimate, 4.0), mesh::MeshRegions(truth, 3.0), settings(), regions);
  EXPECT_EQ(settled, 0u);
  EXPECT_TRUE(by_region.signed_distances);
  expect_same_accuracy(whole, by_region);

  // The truth's samples are other random ones: the same figure within their noise (about
  // 37,000 samples: a standard error of 0.3 %).
  EXPECT_NEAR(by_region.samples_per_m2, whole.samples_per_m2, 1e-9);
  EXPECT_NEAR(static_cast<double>(by_region.reference_samples),
              static_cast<double>(whole.reference_samples), 0.02 * whole.reference_samples);
  for (size_t k = 0; k < whole.scores.size(); ++k) {
    EXPECT_NEAR(by_region.scores[k].completeness, whole.scores[k].completeness, 0.015) << k;
  }
  // The missing ball is missing from both.
  EXPECT_LT(whole.scores.back().completeness, 0.97);

  // A limit on the distance: the far wall is beyond it either way.
  mesh::CompareSettings limited = settings();
  limited.max_dist_m = 0.3;
  const mesh::CompareResult whole_limited = mesh::compare_to_reference(estimate, truth, limited);
  const mesh::CompareResult regions_limited = mesh::compare_by_region(
      mesh::MeshRegions(estimate), mesh::MeshRegions(truth), limited, small_regions());
  EXPECT_GT(whole_limited.beyond_max_dist, 100u);
  EXPECT_EQ(regions_limited.beyond_max_dist, whole_limited.beyond_max_dist);
  expect_same_accuracy(whole_limited, regions_limited);

  // The figures alone, without the per-vertex distances: the same figures.
  mesh::RegionComparisonSettings figures_only = small_regions();
  figures_only.keep_distances = false;
  const mesh::CompareResult lean = mesh::compare_by_region(
      mesh::MeshRegions(estimate, 4.0), mesh::MeshRegions(truth, 3.0), settings(), figures_only);
  EXPECT_TRUE(lean.unsigned_distance_m.empty());
  EXPECT_TRUE(lean.signed_distance_m.empty());
  EXPECT_EQ(lean.points, whole.points);
  EXPECT_NEAR(lean.accuracy.mean_abs, whole.accuracy.mean_abs, 1e-9);
  EXPECT_NEAR(lean.accuracy.std_signed, whole.accuracy.std_signed, 1e-9);
  EXPECT_DOUBLE_EQ(lean.accuracy.median, by_region.accuracy.median);
  EXPECT_DOUBLE_EQ(lean.accuracy.p95, by_region.accuracy.p95);
  EXPECT_EQ(lean.accuracy.max, whole.accuracy.max);
  EXPECT_EQ(lean.histogram_counts, whole.histogram_counts);
  for (size_t k = 0; k < whole.scores.size(); ++k) {
    EXPECT_DOUBLE_EQ(lean.scores[k].precision, whole.scores[k].precision);
  }
}

TEST(RegionComparison, AgainstATiledCloudEqualsTheWholeComparison) {
  // The truth the sensor saw, as the simulator writes it: points, thinned, in tiles.
  const mesh::TriangleMesh truth = street();
  const fs::path dir = fs::path(::testing::TempDir()) / "region_comparison";
  fs::create_directories(dir);
  mesh::TiledPointWriter writer(dir / "seen.ply", {0.05, 6.0, 100000});
  std::mt19937 rng(5);
  for (const Eigen::Vector3f& v : truth.vertices) {
    writer.add(v);
    writer.add(v + Eigen::Vector3f(0.03f, -0.02f, 0.0f));
  }
  writer.finish();
  const mesh::PointFileRegions seen_file(dir / "seen.ply");
  mesh::TriangleMesh seen;
  seen.vertices = mesh::TiledPointFile(dir / "seen.ply").read(Eigen::AlignedBox3d());

  const mesh::TriangleMesh estimate = estimate_of(truth);
  const mesh::CompareResult whole = mesh::compare_to_reference(estimate, seen, settings());
  const mesh::CompareResult by_region =
      mesh::compare_by_region(mesh::MeshRegions(estimate), seen_file, settings(), small_regions());
  EXPECT_FALSE(by_region.signed_distances);  // points without normals give no side
  expect_same_accuracy(whole, by_region);
  EXPECT_EQ(by_region.reference_samples, whole.reference_samples);
  for (size_t k = 0; k < whole.scores.size(); ++k) {
    EXPECT_DOUBLE_EQ(by_region.scores[k].completeness, whole.scores[k].completeness) << k;
  }
}

TEST(RegionComparison, AMovedTruthAndAnEstimateWithoutOrder) {
  // The truth moved into the map's frame, as the aligned evaluation does; the estimate read
  // through a source that gives no vertex order (the figures do not depend on it).
  class Unordered final : public mesh::SurfaceRegions {
   public:
    explicit Unordered(const mesh::TriangleMesh& m) : inner_(m) {}
    Eigen::AlignedBox3d bounds() const override { return inner_.bounds(); }
    bool is_point_cloud() const override { return false; }
    mesh::SurfacePiece read(const Eigen::AlignedBox3d& box) const override {
      mesh::SurfacePiece piece = inner_.read(box);
      piece.source_index.clear();
      return piece;
    }

   private:
    mesh::MeshRegions inner_;
  };
  const mesh::TriangleMesh truth = street();
  const mesh::TriangleMesh estimate = estimate_of(truth);
  const Eigen::Isometry3d T(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                            Eigen::Translation3d(4.0, -2.0, 0.5));
  mesh::TriangleMesh truth_moved = truth;
  for (Eigen::Vector3f& v : truth_moved.vertices) v = T.cast<float>() * v;
  const mesh::CompareResult whole = mesh::compare_to_reference(estimate, truth_moved, settings());
  const mesh::MeshRegions truth_regions(truth);
  mesh::RegionComparisonSettings accuracy_only = small_regions();
  accuracy_only.completeness = false;
  const mesh::CompareResult by_region = mesh::compare_by_region(
      Unordered(estimate), mesh::MovedRegions(truth_regions, T), settings(), accuracy_only);
  EXPECT_EQ(by_region.reference_samples, 0u);
  EXPECT_EQ(by_region.accuracy.count, whole.accuracy.count);
  EXPECT_NEAR(by_region.accuracy.mean_abs, whole.accuracy.mean_abs, 1e-9);
  EXPECT_NEAR(by_region.accuracy.median, whole.accuracy.median, 1e-6);
  EXPECT_NEAR(by_region.accuracy.mean_signed, whole.accuracy.mean_signed, 1e-9);
  EXPECT_EQ(by_region.histogram_counts, whole.histogram_counts);
}

TEST(RegionComparison, EmptyOrDegenerateInputsAreErrors) {
  const mesh::TriangleMesh truth = street();
  const mesh::TriangleMesh nothing;
  EXPECT_THROW(mesh::compare_by_region(mesh::MeshRegions(nothing), mesh::MeshRegions(truth)),
               mesh::MeshError);
  EXPECT_THROW(mesh::compare_by_region(mesh::MeshRegions(truth), mesh::MeshRegions(nothing)),
               mesh::MeshError);
  mesh::TriangleMesh flat;  // three triangles of zero area
  flat.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}, {1, 2, 0}, {0, 0, 1}};
  EXPECT_THROW(mesh::compare_by_region(mesh::MeshRegions(truth), mesh::MeshRegions(flat)),
               mesh::MeshError);
  mesh::TriangleMesh broken = truth;
  broken.vertices[7].y() = std::nanf("");
  EXPECT_THROW(mesh::MeshRegions{broken}, mesh::MeshError);
  mesh::RegionComparisonSettings zero;
  zero.region_size_m = 0.0;
  EXPECT_THROW(
      mesh::compare_by_region(mesh::MeshRegions(truth), mesh::MeshRegions(truth), {}, zero),
      mesh::MeshError);
}

}  // namespace
}  // namespace featsense::test
