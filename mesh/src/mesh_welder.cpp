#include "internal/mesh_welder.hpp"

namespace featsense::mesh::internal {

void MeshWelder::add(const ChunkMesh& part) {
  remap_.assign(part.vertices.size(), -1);
  for (const auto& [local, edge] : part.seam_vertices) {
    const auto found = seam_.find(edge);
    if (found != seam_.end()) remap_[static_cast<size_t>(local)] = found->second;
  }
  for (size_t v = 0; v < part.vertices.size(); ++v) {
    if (remap_[v] >= 0) continue;
    remap_[v] = static_cast<int32_t>(mesh_.vertices.size());
    mesh_.vertices.push_back(part.vertices[v]);
    if (with_normals_) mesh_.normals.push_back(part.normals[v]);
  }
  for (const auto& [local, edge] : part.seam_vertices) {
    seam_.emplace(edge, remap_[static_cast<size_t>(local)]);
  }
  for (const Eigen::Vector3i& t : part.triangles) {
    mesh_.triangles.emplace_back(remap_[static_cast<size_t>(t[0])],
                                 remap_[static_cast<size_t>(t[1])],
                                 remap_[static_cast<size_t>(t[2])]);
  }
}

}  // namespace featsense::mesh::internal
