// Marching cubes over analytic TSDFs spread across chunks (negative chunk coordinates too):
// vertices on the true surface, closed and welded seams, orientation, normals, unobserved
// voxels, threads, bounding box and the dense block variant.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <utility>

#include "common/triangle_corners.hpp"
#include "featsense/mesh/marching_cubes.hpp"
#include "mesh/tsdf_test_fields.hpp"

namespace featsense::test {
namespace {

constexpr double kVoxel = 0.05;
constexpr double kTau = 0.15;
const Eigen::Vector3d kCentre(0.01, -0.02, 0.03);
constexpr double kRadius = 1.3;

storage::MemoryChunkStore sphere_store(const WeightField& weight = {}) {
  storage::MemoryChunkStore store(test_metadata(kVoxel, kTau));
  write_field(
      store, Eigen::Vector3i::Constant(-40), Eigen::Vector3i::Constant(39),
      [](const Eigen::Vector3d& p) { return sphere_distance(p, kCentre, kRadius); }, weight);
  return store;
}

/// Edges used by one triangle (boundary) and by more than two (non-manifold).
struct EdgeCounts {
  size_t edges = 0;
  size_t boundary = 0;
  size_t non_manifold = 0;
  size_t inconsistent = 0;  ///< an edge walked twice in the same direction
};

EdgeCounts count_edges(const mesh::TriangleMesh& m) {
  std::map<std::pair<int, int>, std::pair<int, int>> uses;  // undirected -> (forward, backward)
  for (const Eigen::Vector3i& t : m.triangles) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[k];
      const int b = t[(k + 1) % 3];
      auto& use = uses[{std::min(a, b), std::max(a, b)}];
      (a < b ? use.first : use.second)++;
    }
  }
  EdgeCounts counts;
  counts.edges = uses.size();
  for (const auto& [edge, use] : uses) {
    const int total = use.first + use.second;
    if (total == 1) ++counts.boundary;
    if (total > 2) ++counts.non_manifold;
    if (use.first > 1 || use.second > 1) ++counts.inconsistent;
  }
  return counts;
}

size_t duplicate_positions(const mesh::TriangleMesh& m) {
  std::set<std::array<float, 3>> seen;
  size_t duplicates = 0;
  for (const Eigen::Vector3f& v : m.vertices) {
    if (!seen.insert({v.x(), v.y(), v.z()}).second) ++duplicates;
  }
  return duplicates;
}

TEST(MarchingCubes, SphereIsClosedWeldedAndOnTheSurface) {
  storage::MemoryChunkStore store = sphere_store();
  mesh::MeshingStats stats;
  const mesh::TriangleMesh m = mesh::extract_mesh(store, {}, &stats);
  EXPECT_EQ(stats.chunks, 8u);
  EXPECT_EQ(stats.triangles, m.triangles.size());
  ASSERT_GT(m.triangles.size(), 10000u);
  ASSERT_TRUE(m.has_normals());

  double worst = 0.0;
  double worst_normal = 1.0;
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    const Eigen::Vector3d v = m.vertices[i].cast<double>();
    worst = std::max(worst, std::abs(sphere_distance(v, kCentre, kRadius)));
    worst_normal =
        std::min(worst_normal, m.normals[i].cast<double>().dot((v - kCentre).normalized()));
  }
  EXPECT_LT(worst, 0.02 * kVoxel);
  EXPECT_GT(worst_normal, std::cos(2.0 * M_PI / 180.0));

  const EdgeCounts edges = count_edges(m);
  EXPECT_EQ(edges.boundary, 0u) << "cracks along the chunk seams";
  EXPECT_EQ(edges.non_manifold, 0u);
  EXPECT_EQ(edges.inconsistent, 0u) << "neighbouring triangles disagree on orientation";
  const long euler = static_cast<long>(m.vertices.size()) - static_cast<long>(edges.edges) +
                     static_cast<long>(m.triangles.size());
  EXPECT_EQ(euler, 2);
  EXPECT_EQ(duplicate_positions(m), 0u);

  // Counter-clockwise seen from outside (the positive side).
  for (const Eigen::Vector3i& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices[static_cast<size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = m.vertices[static_cast<size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = m.vertices[static_cast<size_t>(t[2])].cast<double>();
    ASSERT_GT((b - a).cross(c - a).dot((a + b + c) / 3.0 - kCentre), 0.0);
  }
}

TEST(MarchingCubes, PlaneAcrossNegativeChunksIsExact) {
  storage::MemoryChunkStore store(test_metadata(kVoxel, kTau));
  const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -0.3, 1.0).normalized();
  const double offset = 0.0123;
  const auto plane = [&](const Eigen::Vector3d& p) { return normal.dot(p) - offset; };
  write_field(store, Eigen::Vector3i(-70, -70, -20), Eigen::Vector3i(69, 69, 19), plane);
  const mesh::TriangleMesh m = mesh::extract_mesh(store, {});
  ASSERT_GT(m.triangles.size(), 1000u);
  double worst = 0.0;
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    worst = std::max(worst, std::abs(plane(m.vertices[i].cast<double>())));
    ASSERT_GT(m.normals[i].cast<double>().dot(normal), 0.9999) << i;
  }
  EXPECT_LT(worst, 0.01 * kVoxel);
  EXPECT_EQ(duplicate_positions(m), 0u);
  // An open sheet: its border lies only on the outside of the written block.
  EXPECT_EQ(count_edges(m).non_manifold, 0u);
}

TEST(MarchingCubes, BoxFacesAreExact) {
  storage::MemoryChunkStore store(test_metadata(kVoxel, kTau));
  const Eigen::Vector3d lo(-0.83, -1.21, -0.57);
  const Eigen::Vector3d hi(1.07, 0.66, 0.71);
  write_field(store, Eigen::Vector3i::Constant(-40), Eigen::Vector3i::Constant(39),
              [&](const Eigen::Vector3d& p) { return box_distance(p, lo, hi); });
  const mesh::TriangleMesh m = mesh::extract_mesh(store, {});
  ASSERT_GT(m.triangles.size(), 1000u);
  const EdgeCounts edges = count_edges(m);
  EXPECT_EQ(edges.boundary, 0u);
  EXPECT_EQ(edges.non_manifold, 0u);
  size_t checked = 0;
  double worst = 0.0;
  for (const Eigen::Vector3f& vf : m.vertices) {
    const Eigen::Vector3d v = vf.cast<double>();
    // Distances to the six face planes; near a box edge the field is not linear.
    std::array<double, 6> planes{};
    for (int a = 0; a < 3; ++a) {
      planes[static_cast<size_t>(2 * a)] = std::abs(v[a] - lo[a]);
      planes[static_cast<size_t>(2 * a + 1)] = std::abs(v[a] - hi[a]);
    }
    std::sort(planes.begin(), planes.end());
    if (planes[1] < 2.0 * kVoxel) continue;
    ++checked;
    worst = std::max(worst, std::abs(box_distance(v, lo, hi)));
  }
  EXPECT_GT(checked, m.vertices.size() / 2);
  EXPECT_LT(worst, 0.01 * kVoxel);
}

TEST(MarchingCubes, UnobservedAndLightVoxelsMakeNoFaces) {
  // Nothing observed above z = 0.5 m, a quarter measurement for x > 0.4 m.
  storage::MemoryChunkStore store = sphere_store([](const Eigen::Vector3d& p) {
    if (p.z() > 0.5) return 0.0;
    return p.x() > 0.4 ? 0.25 : 2.0;
  });
  mesh::MeshingSettings settings;
  settings.min_weight = 0.5;
  const mesh::TriangleMesh m = mesh::extract_mesh(store, settings);
  ASSERT_GT(m.triangles.size(), 1000u);
  for (const Eigen::Vector3f& v : m.vertices) {
    EXPECT_LT(v.z(), 0.5 + kVoxel);
    EXPECT_LT(v.x(), 0.4 + kVoxel);
  }
  settings.min_weight = 0.2;  // now the light voxels count
  const mesh::TriangleMesh more = mesh::extract_mesh(store, settings);
  EXPECT_GT(more.triangles.size(), m.triangles.size());
  for (const Eigen::Vector3f& v : more.vertices) EXPECT_LT(v.z(), 0.5 + kVoxel);
  settings.min_weight = 0.0;  // still never the unobserved ones
  for (const Eigen::Vector3f& v : mesh::extract_mesh(store, settings).vertices)
    EXPECT_LT(v.z(), 0.5 + kVoxel);
}

TEST(MarchingCubes, OneThreadAndManyGiveTheSameMesh) {
  storage::MemoryChunkStore store = sphere_store();
  mesh::MeshingSettings one;
  one.threads = 1;
  mesh::MeshingSettings many;  // all cores
  const mesh::TriangleMesh a = mesh::extract_mesh(store, one);
  const mesh::TriangleMesh b = mesh::extract_mesh(store, many);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.normals, b.normals);
}

TEST(MarchingCubes, BoundingBoxCrops) {
  storage::MemoryChunkStore store = sphere_store();
  mesh::MeshingSettings settings;
  settings.bbox = Eigen::AlignedBox3d(Eigen::Vector3d(-2, -2, -2), Eigen::Vector3d(2, 2, 0.3));
  const mesh::TriangleMesh cropped = mesh::extract_mesh(store, settings);
  const mesh::TriangleMesh whole = mesh::extract_mesh(store, {});
  ASSERT_GT(cropped.triangles.size(), 1000u);
  EXPECT_LT(cropped.triangles.size(), whole.triangles.size());
  for (const Eigen::Vector3f& v : cropped.vertices) EXPECT_LE(v.z(), 0.3 + 1e-6);
  EXPECT_GT(count_edges(cropped).boundary, 0u);  // the cut is open

  // Bounds off the 8-cube blocks the marcher skips by: the same vertices as the whole mesh,
  // only those inside.
  settings.bbox =
      Eigen::AlignedBox3d(Eigen::Vector3d(-0.93, -1.71, -2), Eigen::Vector3d(1.17, 0.49, 2));
  const mesh::TriangleMesh odd = mesh::extract_mesh(store, settings);
  std::set<std::array<float, 3>> whole_vertices;
  for (const Eigen::Vector3f& v : whole.vertices) whole_vertices.insert({v.x(), v.y(), v.z()});
  ASSERT_GT(odd.triangles.size(), 1000u);
  for (const Eigen::Vector3f& v : odd.vertices) {
    EXPECT_TRUE(settings.bbox->contains(v.cast<double>()));
    EXPECT_EQ(whole_vertices.count({v.x(), v.y(), v.z()}), 1u);
  }
  EXPECT_EQ(count_edges(odd).non_manifold, 0u);

  settings.bbox = Eigen::AlignedBox3d(Eigen::Vector3d(5, 5, 5), Eigen::Vector3d(6, 6, 6));
  mesh::MeshingStats stats;
  EXPECT_TRUE(mesh::extract_mesh(store, settings, &stats).triangles.empty());
  EXPECT_EQ(stats.chunks, 0u);

  settings.bbox = Eigen::AlignedBox3d(Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 1));
  EXPECT_THROW(mesh::extract_mesh(store, settings), std::invalid_argument);
}

TEST(MarchingCubes, DenseBlockGivesTheSameMeshAsTheStore) {
  storage::MemoryChunkStore store = sphere_store();
  const tsdf::Index3 origin{-40, -40, -40};
  const tsdf::Index3 dim{80, 80, 80};
  std::vector<uint32_t> dense(static_cast<size_t>(dim.x * dim.y * dim.z), 0u);
  std::map<storage::ChunkKey, storage::Chunk> chunks;
  for (const storage::ChunkKey& key : store.keys()) chunks[key] = *store.read(key);
  for (int32_t z = 0; z < dim.z; ++z)
    for (int32_t y = 0; y < dim.y; ++y)
      for (int32_t x = 0; x < dim.x; ++x) {
        const int32_t gx = origin.x + x, gy = origin.y + y, gz = origin.z + z;
        const storage::ChunkKey key = storage::chunk_of_voxel(gx, gy, gz);
        dense[static_cast<size_t>(x + dim.x * (y + dim.y * z))] =
            chunks.at(key).at(gx - key.x * storage::kChunkSize, gy - key.y * storage::kChunkSize,
                              gz - key.z * storage::kChunkSize);
      }
  const mesh::TriangleMesh from_store = mesh::extract_mesh(store, {});
  const mesh::TriangleMesh from_block =
      mesh::extract_mesh(dense, origin, dim, kVoxel, kTau, mesh::MeshingSettings{});
  EXPECT_EQ(from_block.vertices, from_store.vertices);
  EXPECT_EQ(from_block.triangles, from_store.triangles);
  EXPECT_THROW(mesh::extract_mesh(std::vector<uint32_t>(5), origin, dim, kVoxel, kTau, {}),
               std::invalid_argument);
}

TEST(MarchingCubes, ChunkByChunkGivesTheStoresMesh) {
  storage::MemoryChunkStore store = sphere_store();
  std::map<storage::ChunkKey, storage::Chunk> chunks;
  for (const storage::ChunkKey& key : store.keys()) chunks[key] = *store.read(key);
  const auto voxel = [&](int32_t gx, int32_t gy, int32_t gz) -> uint32_t {
    const storage::ChunkKey key = storage::chunk_of_voxel(gx, gy, gz);
    const auto found = chunks.find(key);
    if (found == chunks.end()) return 0u;
    return found->second.at(gx - key.x * storage::kChunkSize, gy - key.y * storage::kChunkSize,
                            gz - key.z * storage::kChunkSize);
  };
  mesh::TriangleMesh united;
  for (const storage::ChunkKey& key : store.keys()) {
    constexpr int32_t n = mesh::kPaddedChunkSize;
    std::vector<uint32_t> padded(static_cast<size_t>(n * n * n));
    for (int32_t z = 0; z < n; ++z)
      for (int32_t y = 0; y < n; ++y)
        for (int32_t x = 0; x < n; ++x) {
          padded[static_cast<size_t>(x + n * (y + n * z))] =
              voxel(key.x * storage::kChunkSize - 1 + x, key.y * storage::kChunkSize - 1 + y,
                    key.z * storage::kChunkSize - 1 + z);
        }
    const std::vector<uint32_t> given = padded;
    const mesh::TriangleMesh part = mesh::extract_chunk_mesh(key, padded, kVoxel, 0.5);
    ASSERT_EQ(padded, given) << "the block comes back as it was";
    ASSERT_EQ(part.normals.size(), part.vertices.size());
    united = append_mesh(std::move(united), part);
  }
  const mesh::TriangleMesh whole = mesh::extract_mesh(store, {});
  ASSERT_GT(whole.triangles.size(), 1000u);
  EXPECT_EQ(triangle_corners(united), triangle_corners(whole));
  std::vector<uint32_t> too_small(64);
  EXPECT_THROW(mesh::extract_chunk_mesh({0, 0, 0}, too_small, kVoxel, 0.5), std::invalid_argument);
}

TEST(MarchingCubes, EmptyStoreAndBadSettings) {
  storage::MemoryChunkStore store(test_metadata(kVoxel, kTau));
  EXPECT_TRUE(mesh::extract_mesh(store, {}).vertices.empty());
  mesh::MeshingSettings settings;
  settings.min_weight = -1.0;
  EXPECT_THROW(mesh::extract_mesh(store, settings), std::invalid_argument);
  storage::MemoryChunkStore no_metadata(storage::MapMetadata{});
  EXPECT_THROW(mesh::extract_mesh(no_metadata, {}), std::invalid_argument);
}

}  // namespace
}  // namespace featsense::test
