// Meshing tile by tile against meshing the whole map: the tiles hold exactly the whole mesh's
// triangles, weld by position into its vertices, and stay inside their bounds; simplified
// tiles with their borders held still meet without cracks.

#include <gtest/gtest.h>

#include <map>
#include <stdexcept>
#include <utility>

#include "common/triangle_corners.hpp"
#include "featsense/mesh/map_tiles.hpp"
#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/mesh/mesh_simplification.hpp"
#include "mesh/map_tile_scene.hpp"

namespace featsense::test {
namespace {

/// Edges used by exactly one triangle.
size_t border_edges(const mesh::TriangleMesh& m) {
  std::map<std::pair<int, int>, int> uses;
  for (const Eigen::Vector3i& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k];
      const int b = t[(k + 1) % 3];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  size_t border = 0;
  for (const auto& [edge, count] : uses) border += count == 1 ? 1 : 0;
  return border;
}

TEST(MapTiles, TilesHoldExactlyTheWholeMeshAndWeldIntoIt) {
  storage::MemoryChunkStore store = tile_scene_store();
  const mesh::TriangleMesh whole = mesh::extract_mesh(store, {});
  ASSERT_GT(whole.triangles.size(), 10000u);
  for (int32_t chunks_per_tile : {1, 3}) {
    SCOPED_TRACE("chunks per tile " + std::to_string(chunks_per_tile));
    const mesh::MapTiles tiles(store, chunks_per_tile);
    const std::vector<mesh::TileIndex> indices = tiles.tiles();
    ASSERT_TRUE(std::is_sorted(indices.begin(), indices.end()));
    EXPECT_EQ(indices.front().x, chunks_per_tile == 1 ? -2 : -1);  // floor, not truncation
    EXPECT_EQ(indices.size(), chunks_per_tile == 1 ? 16u : 4u);
    mesh::TriangleMesh together;
    std::vector<mesh::TriangleMesh> parts;
    for (const mesh::TileIndex& index : indices) {
      mesh::MeshingStats stats;
      mesh::TriangleMesh part = tiles.mesh(index, {}, &stats);
      EXPECT_EQ(stats.chunks, tiles.chunk_count(index));
      const Eigen::AlignedBox3d exact = tiles.bounds(index);
      // Vertices are floats: one on the border may round to either side of it.
      const Eigen::AlignedBox3d bounds(exact.min().array() - 1e-5, exact.max().array() + 1e-5);
      for (const Eigen::Vector3f& v : part.vertices) {
        ASSERT_TRUE(bounds.contains(v.cast<double>()))
            << v.transpose() << " outside tile " << index.x << "," << index.y;
      }
      EXPECT_NEAR(exact.sizes().x(), tiles.tile_size_m(), 1e-9);
      together = append_mesh(std::move(together), part);
      parts.push_back(std::move(part));
    }
    EXPECT_EQ(triangle_corners(together), triangle_corners(whole));
    std::vector<const mesh::TriangleMesh*> pointers;
    for (const mesh::TriangleMesh& part : parts) pointers.push_back(&part);
    const mesh::TriangleMesh welded = mesh::weld_by_position(pointers);
    EXPECT_EQ(welded.vertices.size(), whole.vertices.size());
    EXPECT_EQ(border_edges(welded), border_edges(whole));
  }
}

TEST(MapTiles, TileSizeIsRoundedToWholeChunks) {
  const storage::MapMetadata metadata = test_metadata(0.05, 0.15);  // chunks of 3.2 m
  EXPECT_EQ(mesh::chunks_per_tile_for(50.0, metadata), 16);
  EXPECT_EQ(mesh::chunks_per_tile_for(0.1, metadata), 1);
  EXPECT_THROW(mesh::chunks_per_tile_for(0.0, metadata), std::invalid_argument);
  EXPECT_THROW(mesh::chunks_per_tile_for(std::nan(""), metadata), std::invalid_argument);
  storage::MemoryChunkStore store(metadata);
  EXPECT_THROW(mesh::MapTiles(store, 0), std::invalid_argument);
  EXPECT_TRUE(mesh::MapTiles(store, 4).tiles().empty());
}

TEST(MeshSimplification, TilesSimplifiedWithTheirCutsHeldMeetWithoutCracks) {
  storage::MemoryChunkStore store(test_metadata(kTileSceneVoxel, kTileSceneTau));
  const Eigen::Vector3d centre(0.01, -0.02, 0.03);
  write_field(store, Eigen::Vector3i::Constant(-40), Eigen::Vector3i::Constant(39),
              [&](const Eigen::Vector3d& p) { return sphere_distance(p, centre, 1.3); });
  const mesh::TriangleMesh whole = mesh::extract_mesh(store, {});
  ASSERT_EQ(border_edges(whole), 0u);
  const mesh::MapTiles tiles(store, 1);
  ASSERT_EQ(tiles.tiles().size(), 4u);  // quarters of the ball, cut along x = 0 and y = 0
  const auto cut = static_cast<float>(tiles.cut_m(0));
  for (bool hold : {true, false}) {
    std::vector<mesh::TriangleMesh> simplified;
    double worst_error = 0.0;
    for (const mesh::TileIndex& index : tiles.tiles()) {
      const mesh::TriangleMesh quarter = tiles.mesh(index, {});
      std::vector<bool> held(quarter.vertices.size(), false);
      size_t on_cut = 0;
      for (size_t v = 0; v < held.size() && hold; ++v) {
        held[v] = quarter.vertices[v].x() == cut || quarter.vertices[v].y() == cut;
        on_cut += held[v] ? 1 : 0;
      }
      if (hold) {
        EXPECT_GT(on_cut, 50u);
      }
      mesh::SimplifySettings settings;
      settings.target_ratio = 0.25;
      mesh::SimplifiedMesh s = mesh::simplify_mesh(quarter, settings, held);
      worst_error = std::max(worst_error, s.error_m);
      ASSERT_TRUE(s.mesh.has_normals());
      // Edge collapse keeps vertices where they were: on the ball's surface.
      for (const Eigen::Vector3f& v : s.mesh.vertices)
        ASSERT_LT(std::abs(sphere_distance(v.cast<double>(), centre, 1.3)), 0.001);
      simplified.push_back(std::move(s.mesh));
    }
    std::vector<const mesh::TriangleMesh*> pointers;
    for (const mesh::TriangleMesh& part : simplified) pointers.push_back(&part);
    const mesh::TriangleMesh welded = mesh::weld_by_position(pointers);
    if (hold) {
      EXPECT_EQ(border_edges(welded), 0u) << "cracks between the simplified tiles";
      EXPECT_LT(welded.triangles.size(), whole.triangles.size() * 35 / 100);
      EXPECT_GT(worst_error, 0.0);
      EXPECT_LT(worst_error, 0.02);
    } else {
      EXPECT_GT(border_edges(welded), 0u) << "without holding the cuts they should move apart";
    }
  }
}

TEST(MeshSimplification, OtherOpenBordersAreSimplifiedAlongThemselves) {
  // A flat square with a hole: nothing held, the outer border and the hole's rim thin out too.
  storage::MemoryChunkStore store(test_metadata(kTileSceneVoxel, kTileSceneTau));
  write_field(
      store, Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(60, 60, 20),
      [](const Eigen::Vector3d& p) { return p.z() - 0.5; },
      [](const Eigen::Vector3d& p) {
        return (p - Eigen::Vector3d(1.5, 1.5, p.z())).norm() < 0.5 ? 0.0 : 1.0;
      });
  const mesh::TriangleMesh plate = mesh::extract_mesh(store, {});
  const size_t border_before = border_edges(plate);
  ASSERT_GT(border_before, 100u);
  mesh::SimplifySettings settings;
  settings.target_ratio = 0.05;
  const mesh::SimplifiedMesh s = mesh::simplify_mesh(plate, settings);
  EXPECT_LT(border_edges(s.mesh), border_before / 2);
  EXPECT_LT(s.error_m, 1e-3);  // a plane stays a plane
}

TEST(MeshSimplification, BadSettingsAndEmptyMeshes) {
  mesh::SimplifySettings settings;
  EXPECT_TRUE(mesh::simplify_mesh({}, settings).mesh.triangles.empty());
  settings.target_ratio = 0.0;
  EXPECT_THROW(mesh::simplify_mesh({}, settings), std::invalid_argument);
  settings.target_ratio = 0.5;
  settings.max_error_m = -1.0;
  EXPECT_THROW(mesh::simplify_mesh({}, settings), std::invalid_argument);
  settings.max_error_m = 1.0;
  mesh::TriangleMesh one;
  one.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.triangles = {{0, 1, 2}};
  EXPECT_THROW(mesh::simplify_mesh(one, settings, {true}), std::invalid_argument);
}

}  // namespace
}  // namespace featsense::test
