// PLY writer: geometry, normals, colours and float layers per vertex, then faces.

#include <cstring>
#include <fstream>

#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::viewer_export {
namespace {

/// Appends a value in little-endian byte order (the machine's own on x86 and ARM).
template <typename T>
void put(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out->append(bytes, sizeof(T));
}

}  // namespace

void write_ply_mesh(const std::string& path, const mesh::TriangleMesh& mesh,
                    const MeshAttributes& attributes, const PlyWriteSettings& settings) {
  const size_t n = mesh.vertices.size();
  for (const VertexScalar& scalar : attributes.scalars) {
    if (scalar.values.size() != n) {
      throw PlyError(path + ": layer '" + scalar.name + "' has " +
                     std::to_string(scalar.values.size()) + " values for " + std::to_string(n) +
                     " vertices");
    }
  }
  if (!attributes.colors.empty() && attributes.colors.size() != n) {
    throw PlyError(path + ": colours do not match the vertices");
  }
  const bool normals = mesh.has_normals();
  std::string header = "ply\nformat ";
  header += settings.binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  header += "comment featsense\nelement vertex " + std::to_string(n) + "\n";
  header += "property float x\nproperty float y\nproperty float z\n";
  if (normals) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (!attributes.colors.empty()) {
    header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  for (const VertexScalar& scalar : attributes.scalars) {
    header += "property float scalar_" + scalar.name + "\n";
  }
  if (!mesh.triangles.empty()) {
    header += "element face " + std::to_string(mesh.triangles.size()) + "\n";
    header += "property list uchar int vertex_indices\n";
  }
  header += "end_header\n";

  std::string body;
  for (size_t i = 0; i < n; ++i) {
    std::vector<float> floats(mesh.vertices[i].data(), mesh.vertices[i].data() + 3);
    if (normals) floats.insert(floats.end(), mesh.normals[i].data(), mesh.normals[i].data() + 3);
    if (settings.binary) {
      for (float f : floats) put(&body, f);
      if (!attributes.colors.empty()) {
        for (int k = 0; k < 3; ++k) put(&body, attributes.colors[i][k]);
      }
      for (const VertexScalar& scalar : attributes.scalars) put(&body, scalar.values[i]);
    } else {
      std::string line;
      char number[32];
      for (float f : floats) {
        std::snprintf(number, sizeof number, "%.9g ", static_cast<double>(f));
        line += number;
      }
      if (!attributes.colors.empty()) {
        for (int k = 0; k < 3; ++k) line += std::to_string(attributes.colors[i][k]) + " ";
      }
      for (const VertexScalar& scalar : attributes.scalars) {
        std::snprintf(number, sizeof number, "%.9g ", static_cast<double>(scalar.values[i]));
        line += number;
      }
      line.back() = '\n';
      body += line;
    }
  }
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    if (settings.binary) {
      put(&body, uint8_t{3});
      for (int k = 0; k < 3; ++k) put(&body, static_cast<int32_t>(tri[k]));
    } else {
      body += "3 " + std::to_string(tri[0]) + " " + std::to_string(tri[1]) + " " +
              std::to_string(tri[2]) + "\n";
    }
  }
  std::ofstream out(path, std::ios::binary);
  if (!out) throw PlyError(path + ": cannot write");
  out << header << body;
  if (!out) throw PlyError(path + ": write failed");
}

}  // namespace featsense::viewer_export
