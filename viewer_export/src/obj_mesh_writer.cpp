// OBJ writer: vertices (with colours), normals, faces, and an MTL where colours are present.

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "featsense/viewer_export/obj_mesh_io.hpp"

namespace featsense::viewer_export {
namespace {

void write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw MeshFileError(path + ": cannot open for writing");
  out << text;
  out.close();
  if (!out) throw MeshFileError(path + ": write failed");
}

}  // namespace

void write_obj_mesh(const std::string& path, const mesh::TriangleMesh& mesh,
                    const MeshAttributes& attributes) {
  const size_t n = mesh.vertices.size();
  const bool colors = !attributes.colors.empty();
  if (colors && attributes.colors.size() != n) {
    throw MeshFileError(path + ": " + std::to_string(attributes.colors.size()) + " colours for " +
                        std::to_string(n) + " vertices");
  }
  const bool normals = mesh.has_normals();
  std::string text = "# featsense mesh, map frame, metres\n";
  const std::filesystem::path mtl_path = std::filesystem::path(path).replace_extension(".mtl");
  if (colors) {
    text += "mtllib " + mtl_path.filename().string() + "\nusemtl vertex_colors\n";
  }
  char line[160];
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f& v = mesh.vertices[i];
    int length = std::snprintf(line, sizeof(line), "v %.9g %.9g %.9g", static_cast<double>(v.x()),
                               static_cast<double>(v.y()), static_cast<double>(v.z()));
    if (colors) {
      const auto& c = attributes.colors[i];
      length += std::snprintf(line + length, sizeof(line) - static_cast<size_t>(length),
                              " %.6f %.6f %.6f", c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
    }
    text.append(line, static_cast<size_t>(length));
    text += '\n';
  }
  if (normals) {
    for (const Eigen::Vector3f& nv : mesh.normals) {
      const int length =
          std::snprintf(line, sizeof(line), "vn %.9g %.9g %.9g\n", static_cast<double>(nv.x()),
                        static_cast<double>(nv.y()), static_cast<double>(nv.z()));
      text.append(line, static_cast<size_t>(length));
    }
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    // OBJ indices start at 1; with normals each corner names its vertex's own normal.
    const int length =
        normals ? std::snprintf(line, sizeof(line), "f %d//%d %d//%d %d//%d\n", t[0] + 1, t[0] + 1,
                                t[1] + 1, t[1] + 1, t[2] + 1, t[2] + 1)
                : std::snprintf(line, sizeof(line), "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
    text.append(line, static_cast<size_t>(length));
  }
  write_file(path, text);
  if (colors) {
    write_file(mtl_path.string(),
               "# featsense: white, modulated by the OBJ's vertex colours\n"
               "newmtl vertex_colors\nKa 0 0 0\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1\n");
  }
}

}  // namespace featsense::viewer_export
