#include "featsense/mesh/triangle_mesh.hpp"

#include <Eigen/Geometry>

namespace featsense::mesh {

void validate(const TriangleMesh& mesh, const std::string& what) {
  const auto n = static_cast<int>(mesh.vertices.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      if (tri[k] < 0 || tri[k] >= n) {
        throw MeshError(what + ": triangle " + std::to_string(t) + " refers to vertex " +
                        std::to_string(tri[k]) + " of " + std::to_string(n));
      }
    }
  }
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!mesh.vertices[v].allFinite()) {
      throw MeshError(what + ": vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
  if (!mesh.normals.empty() && mesh.normals.size() != mesh.vertices.size()) {
    throw MeshError(what + ": " + std::to_string(mesh.normals.size()) + " normals for " +
                    std::to_string(mesh.vertices.size()) + " vertices");
  }
}

double surface_area_m2(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[static_cast<size_t>(tri[0])].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[static_cast<size_t>(tri[1])].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[static_cast<size_t>(tri[2])].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

}  // namespace featsense::mesh
