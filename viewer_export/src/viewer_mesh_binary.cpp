#include "featsense/viewer_export/viewer_mesh_binary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "featsense/viewer_export/mesh_file_error.hpp"

namespace featsense::viewer_export {
namespace {

static_assert(sizeof(Eigen::Vector3f) == 12 && sizeof(Eigen::Vector3i) == 12,
              "the blocks are copied as packed arrays");

/// Appends `bytes` bytes at the end of `out` (the host is little-endian, as the page reads).
void append(std::string& out, const void* data, std::size_t bytes) {
  out.append(static_cast<const char*>(data), bytes);
}

void append_u32(std::string& out, std::size_t value) {
  const auto v = static_cast<uint32_t>(value);
  append(out, &v, sizeof(v));
}

/// The normals' block: 3 bytes per vertex, padded so that the indices after it are aligned.
std::size_t normal_bytes(std::size_t vertices) { return (3 * vertices + 3) / 4 * 4; }

}  // namespace

std::size_t viewer_mesh_bytes(std::size_t vertices, std::size_t triangles, std::size_t layers) {
  return kViewerMeshHeaderBytes + vertices * (3 + layers) * sizeof(float) + normal_bytes(vertices) +
         triangles * 3 * sizeof(uint32_t);
}

std::string encode_viewer_mesh(const mesh::TriangleMesh& mesh,
                               const std::vector<VertexScalar>& layers) {
  const std::size_t n = mesh.vertices.size();
  if (mesh.normals.size() != n)
    throw MeshFileError("viewer mesh: " + std::to_string(mesh.normals.size()) + " normals for " +
                        std::to_string(n) + " vertices");
  for (const VertexScalar& layer : layers) {
    if (layer.values.size() != n)
      throw MeshFileError("viewer mesh: layer " + layer.name + " has " +
                          std::to_string(layer.values.size()) + " values for " + std::to_string(n) +
                          " vertices");
  }
  std::string out;
  out.reserve(viewer_mesh_bytes(n, mesh.triangles.size(), layers.size()));
  append(out, kViewerMeshMagic, sizeof(kViewerMeshMagic));
  append_u32(out, n);
  append_u32(out, mesh.triangles.size());
  append_u32(out, layers.size());
  out.append(kViewerMeshHeaderBytes - out.size(), '\0');
  append(out, mesh.vertices.data(), n * sizeof(Eigen::Vector3f));
  const std::size_t normals_start = out.size();
  for (const Eigen::Vector3f& normal : mesh.normals) {
    for (int k = 0; k < 3; ++k) {
      const float scaled = std::clamp(normal[k], -1.0f, 1.0f) * 127.0f;
      out.push_back(static_cast<char>(static_cast<int8_t>(std::lround(scaled))));
    }
  }
  out.append(normals_start + normal_bytes(n) - out.size(), '\0');
  // Indices are never negative in a valid mesh: the int32 bits are the uint32 values.
  append(out, mesh.triangles.data(), mesh.triangles.size() * sizeof(Eigen::Vector3i));
  for (const VertexScalar& layer : layers) append(out, layer.values.data(), n * sizeof(float));
  return out;
}

}  // namespace featsense::viewer_export
