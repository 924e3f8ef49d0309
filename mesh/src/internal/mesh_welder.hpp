#pragma once
/// Joins the meshes of chunks into one, merging the vertices that neighbouring chunks both
/// made on their shared faces. Chunks must come in a fixed order for a fixed result.

#include <cstdint>
#include <unordered_map>

#include "featsense/mesh/triangle_mesh.hpp"
#include "internal/chunk_mesher.hpp"

namespace featsense::mesh::internal {

class MeshWelder {
 public:
  explicit MeshWelder(bool with_normals) : with_normals_(with_normals) {}

  void add(const ChunkMesh& part);
  TriangleMesh take() { return std::move(mesh_); }

 private:
  bool with_normals_;
  TriangleMesh mesh_;
  /// Seam vertices already in the mesh, by edge: only those, since no other vertex can be
  /// made by two chunks.
  std::unordered_map<EdgeKey, int32_t, EdgeKeyHash> seam_;
  std::vector<int32_t> remap_;
};

}  // namespace featsense::mesh::internal
