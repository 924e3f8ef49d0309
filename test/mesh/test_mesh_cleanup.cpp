// Mesh cleanup: floating noise removed, non-manifold vertices and edges split, holes filled,
// simplification that keeps a closed surface closed and reports its error.

#include <gtest/gtest.h>

#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/mesh/mesh_cleanup.hpp"
#include "mesh/mesh_test_shapes.hpp"
#include "mesh/tsdf_test_fields.hpp"

namespace featsense::test {
namespace {

constexpr double kVoxel = 0.05;
constexpr double kRadius = 1.3;
const Eigen::Vector3d kCentre(0.01, -0.02, 0.03);

mesh::TriangleMesh sphere_mesh() {
  storage::MemoryChunkStore store(test_metadata(kVoxel, 0.15));
  write_field(store, Eigen::Vector3i::Constant(-40), Eigen::Vector3i::Constant(39),
              [](const Eigen::Vector3d& p) { return sphere_distance(p, kCentre, kRadius); });
  return mesh::extract_mesh(store, {});
}

/// Appends `part` (moved by `offset`) to `mesh`.
void append(mesh::TriangleMesh& mesh, const mesh::TriangleMesh& part,
            const Eigen::Vector3f& offset) {
  const auto base = static_cast<int>(mesh.vertices.size());
  for (const Eigen::Vector3f& v : part.vertices) mesh.vertices.push_back(v + offset);
  for (const Eigen::Vector3i& t : part.triangles)
    mesh.triangles.push_back(t + Eigen::Vector3i::Constant(base));
}

mesh::CleanupSettings no_self_intersection_check() {
  mesh::CleanupSettings settings;
  settings.check_self_intersections = false;
  return settings;
}

TEST(MeshCleanup, RemovesFloatingNoiseAndKeepsNormals) {
  const mesh::TriangleMesh sphere = sphere_mesh();
  mesh::TriangleMesh noisy = sphere;
  noisy.normals.clear();
  append(noisy, icosphere(0.05f, 1), Eigen::Vector3f(3, 0, 0));
  noisy.normals = sphere.normals;
  noisy.normals.resize(noisy.vertices.size(), Eigen::Vector3f::UnitZ());

  mesh::CleanupSettings settings = no_self_intersection_check();
  settings.min_component_area_m2 = 0.1;
  const mesh::CleanupReport report = mesh::clean_mesh(noisy, settings);
  EXPECT_EQ(report.removed_components, 1u);
  EXPECT_EQ(report.removed_component_triangles, 80u);
  EXPECT_EQ(noisy.triangles.size(), sphere.triangles.size());
  EXPECT_TRUE(report.is_closed);
  EXPECT_TRUE(report.is_manifold);
  EXPECT_TRUE(report.is_valid);
  ASSERT_TRUE(noisy.has_normals());
  for (size_t i = 0; i < noisy.vertices.size(); ++i) {
    const Eigen::Vector3d outward = (noisy.vertices[i].cast<double>() - kCentre).normalized();
    ASSERT_GT(noisy.normals[i].cast<double>().dot(outward), 0.999) << i;
  }

  mesh::TriangleMesh by_count = sphere;
  append(by_count, icosphere(0.05f, 1), Eigen::Vector3f(3, 0, 0));
  by_count.normals.clear();
  settings.min_component_area_m2 = 0.0;
  settings.min_component_triangles = 100;
  EXPECT_EQ(mesh::clean_mesh(by_count, settings).removed_components, 1u);
  EXPECT_FALSE(by_count.has_normals());
}

TEST(MeshCleanup, SplitsNonManifoldVerticesAndEdges) {
  // Two closed cubes touching at one corner (a pinched vertex) ...
  mesh::TriangleMesh pinched = box_mesh(0.5f);
  append(pinched, box_mesh(0.5f), Eigen::Vector3f(1, 1, 1));
  // ... and three triangles on one edge (a fin).
  const auto base = static_cast<int>(pinched.vertices.size());
  for (const Eigen::Vector3f& v :
       {Eigen::Vector3f(5, 0, 0), Eigen::Vector3f(5, 1, 0), Eigen::Vector3f(6, 0, 0),
        Eigen::Vector3f(4, 0, 0), Eigen::Vector3f(5, 0, 1)}) {
    pinched.vertices.push_back(v);
  }
  for (int k = 2; k < 5; ++k) pinched.triangles.emplace_back(base, base + 1, base + k);

  mesh::CleanupSettings strict = no_self_intersection_check();
  strict.fix_non_manifold = false;
  mesh::TriangleMesh copy = pinched;
  EXPECT_THROW(mesh::clean_mesh(copy, strict), mesh::MeshError);

  const mesh::CleanupReport report = mesh::clean_mesh(pinched, mesh::CleanupSettings{});
  EXPECT_GE(report.non_manifold_vertices_fixed, 3u);  // the corner, and the fin's two ends
  EXPECT_TRUE(report.is_valid);
  EXPECT_TRUE(report.is_manifold);
  EXPECT_FALSE(report.is_closed);  // the fin's triangles are open
  EXPECT_EQ(pinched.triangles.size(), 24u + 3u);

  mesh::TriangleMesh cubes = box_mesh(0.5f);
  append(cubes, box_mesh(0.5f), Eigen::Vector3f(1, 1, 1));
  const mesh::CleanupReport closed = mesh::clean_mesh(cubes, mesh::CleanupSettings{});
  EXPECT_TRUE(closed.is_closed);
  EXPECT_TRUE(closed.is_manifold);
  EXPECT_EQ(cubes.vertices.size(), 16u);  // the shared corner split in two
}

TEST(MeshCleanup, FillsHolesUpToTheirPerimeter) {
  mesh::TriangleMesh open = sphere_mesh();
  std::vector<Eigen::Vector3i> kept;
  for (const Eigen::Vector3i& t : open.triangles) {
    const float z = (open.vertices[static_cast<size_t>(t[0])].z() +
                     open.vertices[static_cast<size_t>(t[1])].z() +
                     open.vertices[static_cast<size_t>(t[2])].z()) /
                    3.0f;
    if (z < 1.2f) kept.push_back(t);  // a cap of radius about 0.55 m cut off
  }
  open.triangles = kept;
  mesh::TriangleMesh small_limit = open;
  mesh::CleanupSettings settings = no_self_intersection_check();
  settings.max_hole_perimeter_m = 1.0;
  mesh::CleanupReport report = mesh::clean_mesh(small_limit, settings);
  EXPECT_EQ(report.holes_filled, 0u);
  EXPECT_EQ(report.holes_left, 1u);
  EXPECT_FALSE(report.is_closed);

  settings.max_hole_perimeter_m = 10.0;
  report = mesh::clean_mesh(open, settings);
  EXPECT_EQ(report.holes_filled, 1u) << report.holes_left;
  EXPECT_TRUE(report.is_closed) << report.border_edges;
  EXPECT_TRUE(report.is_manifold);
  ASSERT_TRUE(open.has_normals());
}

TEST(MeshCleanup, SimplifiedSphereStaysClosedWithABoundedError) {
  mesh::TriangleMesh sphere = sphere_mesh();
  const size_t before = sphere.triangles.size();
  mesh::CleanupSettings settings;
  settings.simplify_ratio = 0.2;
  const mesh::CleanupReport report = mesh::clean_mesh(sphere, settings);
  EXPECT_NEAR(static_cast<double>(sphere.triangles.size()), 0.2 * static_cast<double>(before),
              0.02 * static_cast<double>(before));
  EXPECT_TRUE(report.is_closed);
  EXPECT_TRUE(report.is_manifold);
  EXPECT_TRUE(report.is_valid);
  EXPECT_EQ(report.self_intersections, 0u);
  // Chords of edges about 2.5 voxels long on a 1.3 m sphere sag by about 1 mm.
  EXPECT_GT(report.simplification_max_error_m, 0.0);
  EXPECT_LT(report.simplification_max_error_m, 0.1 * kVoxel);
  EXPECT_LE(report.simplification_mean_error_m, report.simplification_max_error_m);
  for (const Eigen::Vector3f& v : sphere.vertices) {
    ASSERT_LT(std::abs(sphere_distance(v.cast<double>(), kCentre, kRadius)),
              report.simplification_max_error_m + 0.02 * kVoxel);
  }
  ASSERT_TRUE(sphere.has_normals());
}

TEST(MeshCleanup, APieceCleanedApartKeepsWhatReachesItsCutAndLeavesTheCutOpen) {
  // A tile of a floor, cut at x = 1 from its neighbour: a hole in its middle, a speck of noise
  // inside it and one that reaches the cut (its rest lies in the neighbour).
  mesh::TriangleMesh tile = grid_plane(0, 1, 0, 1, 0, 20);
  std::vector<Eigen::Vector3i> kept;
  for (const Eigen::Vector3i& t : tile.triangles) {
    const Eigen::Vector3f c =
        (tile.vertices[static_cast<size_t>(t[0])] + tile.vertices[static_cast<size_t>(t[1])] +
         tile.vertices[static_cast<size_t>(t[2])]) /
        3.0f;
    if ((c - Eigen::Vector3f(0.5f, 0.5f, 0)).norm() > 0.08f) kept.push_back(t);
  }
  tile.triangles = kept;
  append(tile, grid_plane(0, 0.05f, 0, 0.05f, 0.5f, 1), {0.4f, 0.4f, 0});   // inside
  append(tile, grid_plane(0, 0.05f, 0, 0.05f, 0.5f, 1), {0.95f, 0.4f, 0});  // at the cut
  mesh::CleanupSettings settings = no_self_intersection_check();
  settings.min_component_area_m2 = 0.01;
  settings.max_hole_perimeter_m = 1.0;

  mesh::TriangleMesh whole_rules = tile;
  mesh::CleanupReport report = mesh::clean_mesh(whole_rules, settings);
  EXPECT_EQ(report.removed_components, 2u) << "without a cut both specks are noise";

  settings.on_cut = [](const Eigen::Vector3f& p) { return p.x() == 1.0f; };
  report = mesh::clean_mesh(tile, settings);
  EXPECT_EQ(report.removed_components, 1u);
  EXPECT_EQ(report.components_kept_on_cuts, 1u);
  EXPECT_EQ(report.holes_filled, 1u);
  EXPECT_EQ(report.borders_on_cuts, 2u) << "the floor's edge and the speck's pass the cut";
  size_t on_cut = 0;
  for (const Eigen::Vector3f& v : tile.vertices) on_cut += v.x() == 1.0f ? 1 : 0;
  EXPECT_EQ(on_cut, 21u + 2u) << "the cut's vertices stay for the neighbour to meet";
}

TEST(MeshCleanup, RejectsBadSettings) {
  mesh::TriangleMesh cube = box_mesh(0.5f);
  mesh::CleanupSettings settings;
  settings.simplify_ratio = 0.0;
  EXPECT_THROW(mesh::clean_mesh(cube, settings), mesh::MeshError);
  settings.simplify_ratio = 1.5;
  EXPECT_THROW(mesh::clean_mesh(cube, settings), mesh::MeshError);
  settings = {};
  settings.max_hole_perimeter_m = -1.0;
  EXPECT_THROW(mesh::clean_mesh(cube, settings), mesh::MeshError);
}

}  // namespace
}  // namespace featsense::test
