#pragma once
/// Marching cubes over the TSDF: the global map (a chunk store) or a dense block of the local
/// map, into one welded triangle mesh in the map frame (metres).
///
/// A cube joins eight neighbouring voxel centres ((i + 0.5) * voxel_size_m per axis). It gets
/// faces only where all eight voxels were observed with at least `min_weight` measurements;
/// vertices sit on cube edges where the value changes sign, placed by linear interpolation.
/// Triangles are counter-clockwise seen from the positive (free) side; vertex normals are the
/// TSDF gradient (central differences) pointing to the positive side. Chunks are meshed in
/// parallel and welded along their seams, so the result is one mesh without cracks or
/// duplicate vertices, in the same order whatever the number of threads.

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/storage/chunk_store.hpp"
#include "featsense/tsdf/vec3.hpp"

namespace featsense::mesh {

struct MeshingSettings {
  /// Cubes need this many measurements (weight / 64) at each of their eight voxels. Half a
  /// measurement keeps surfaces seen by a single scan (their voxels have full weight) and
  /// drops the fringe far behind surfaces, where one scan's weight has faded out and the
  /// distance is a guess.
  double min_weight = 0.5;
  /// Only cubes whose eight voxel centres lie inside this box (metres, map frame).
  std::optional<Eigen::AlignedBox3d> bbox;
  int threads = 0;  ///< 0 = all cores (TBB)
};

struct MeshingStats {
  size_t chunks = 0;     ///< chunks considered (stored, inside the bbox)
  size_t voxels = 0;     ///< voxels of those chunks (chunks * 64^3)
  size_t triangles = 0;  ///< of the result
  size_t vertices = 0;   ///< of the result
  double seconds = 0;    ///< wall time of the extraction
};

/// Meshes every stored chunk (inside the bbox). Reads the store from one thread at a time and
/// keeps only the chunks in flight (and a few rows of neighbours) in memory besides the mesh.
/// Throws std::invalid_argument for bad settings or metadata (voxel size or tau not positive).
TriangleMesh extract_mesh(storage::ChunkStore& store, const MeshingSettings& settings,
                          MeshingStats* stats = nullptr);

/// Meshes a dense block of packed voxels (tsdf/voxel.hpp), x fastest: voxel (x, y, z) of the
/// block is global voxel origin + (x, y, z), at index x + dim.x * (y + dim.y * z). Voxels
/// outside the block count as unobserved. For live previews of the local map.
TriangleMesh extract_mesh(const std::vector<uint32_t>& voxels, tsdf::Index3 origin,
                          tsdf::Index3 dim, double voxel_size_m, double truncation_m,
                          const MeshingSettings& settings, MeshingStats* stats = nullptr);

/// Voxels along each edge of a chunk's padded block (extract_chunk_mesh): one before the chunk
/// and two after it.
inline constexpr int32_t kPaddedChunkSize = storage::kChunkSize + 3;

/// Meshes one chunk from its padded block: the voxels of global indices key * 64 - 1 to
/// key * 64 + 65 per axis, x fastest (kPaddedChunkSize^3 of them). The result holds the
/// cubes whose lowest voxel lies in the chunk, with normals: the chunk's part of extract_mesh
/// over a store of the same voxels, not welded to its neighbours' parts. For previews of a map
/// being made, a chunk at a time. `padded` is borrowed and given back as it was (its memory can
/// hold the next block). Throws std::invalid_argument for a block of another size or bad
/// settings.
TriangleMesh extract_chunk_mesh(const storage::ChunkKey& key, std::vector<uint32_t>& padded,
                                double voxel_size_m, double min_weight);

}  // namespace featsense::mesh
