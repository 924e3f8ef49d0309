#pragma once
/// Marching cubes over one padded chunk: the cubes whose lower corner lies in the chunk.

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "featsense/tsdf/vec3.hpp"
#include "internal/padded_block.hpp"

namespace featsense::mesh::internal {

/// A cube edge on the global voxel grid: from voxel (x, y, z) one step along `axis`. The
/// vertex on it is the same whichever chunk computes it, which is what welding relies on.
struct EdgeKey {
  int32_t x = 0;
  int32_t y = 0;
  int32_t z = 0;
  int32_t axis = 0;

  friend bool operator==(const EdgeKey& a, const EdgeKey& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z && a.axis == b.axis;
  }
};

struct EdgeKeyHash {
  std::size_t operator()(const EdgeKey& k) const {
    const uint64_t h = static_cast<uint64_t>(static_cast<uint32_t>(k.x)) * 73856093u ^
                       static_cast<uint64_t>(static_cast<uint32_t>(k.y)) * 19349663u ^
                       static_cast<uint64_t>(static_cast<uint32_t>(k.z)) * 83492791u ^
                       static_cast<uint64_t>(k.axis) * 2654435761u;
    return static_cast<std::size_t>(h);
  }
};

struct ChunkMesh {
  std::vector<Eigen::Vector3f> vertices;   ///< map frame, metres
  std::vector<Eigen::Vector3f> normals;    ///< unit, towards the positive side
  std::vector<Eigen::Vector3i> triangles;  ///< indices into `vertices`
  /// Vertices that cubes of neighbouring chunks may also have made (on the chunk's faces).
  std::vector<std::pair<int32_t, EdgeKey>> seam_vertices;
};

struct ChunkMeshingParameters {
  double voxel_size_m = 0.0;
  uint32_t min_weight_fixed = 1;     ///< weight * 64; at least 1 (unobserved voxels never count)
  tsdf::Index3 cube_begin{0, 0, 0};  ///< chunk-local cube range
  tsdf::Index3 cube_end{storage::kChunkSize, storage::kChunkSize, storage::kChunkSize};
};

/// Meshes the cubes in [cube_begin, cube_end) of the block's chunk. Thread-safe.
ChunkMesh mesh_chunk(const PaddedBlock& block, const ChunkMeshingParameters& parameters);

}  // namespace featsense::mesh::internal
