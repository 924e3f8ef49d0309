// OBJ reader: v (optionally with colour), vn and f statements; the rest is skipped.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "featsense/viewer_export/obj_mesh_io.hpp"

namespace featsense::viewer_export {
namespace {

/// Resolves a 1-based (or negative, counted from the end) OBJ index into 0-based.
int resolve(long index, size_t count, const std::string& where) {
  const long resolved = index > 0 ? index - 1 : static_cast<long>(count) + index;
  if (index == 0 || resolved < 0 || resolved >= static_cast<long>(count)) {
    throw MeshFileError(where + ": index " + std::to_string(index) + " out of range");
  }
  return static_cast<int>(resolved);
}

/// The integer of one corner's field; a malformed number names the line.
long parse_index(const std::string& text, const std::string& where) {
  try {
    return std::stol(text);
  } catch (const std::exception&) {
    throw MeshFileError(where + ": bad index '" + text + "'");
  }
}

uint8_t to_byte(double value) {
  return static_cast<uint8_t>(std::lround(std::clamp(value, 0.0, 1.0) * 255.0));
}

}  // namespace

mesh::TriangleMesh read_obj_mesh(const std::string& path, MeshAttributes* colors) {
  std::ifstream in(path);
  if (!in) throw MeshFileError(path + ": cannot open");
  mesh::TriangleMesh mesh;
  std::vector<Eigen::Vector3f> normal_list;
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> color_list;
  std::vector<int> normal_of_vertex;
  std::string line;
  size_t line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string where = path + " line " + std::to_string(line_number);
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "v") {
      double x = 0, y = 0, z = 0;
      if (!(words >> x >> y >> z)) throw MeshFileError(where + ": a vertex needs x y z");
      mesh.vertices.emplace_back(static_cast<float>(x), static_cast<float>(y),
                                 static_cast<float>(z));
      double r = 0, g = 0, b = 0;
      if (words >> r >> g >> b) color_list.emplace_back(to_byte(r), to_byte(g), to_byte(b));
    } else if (keyword == "vn") {
      double x = 0, y = 0, z = 0;
      if (!(words >> x >> y >> z)) throw MeshFileError(where + ": a normal needs x y z");
      normal_list.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    } else if (keyword == "f") {
      std::vector<int> corners;
      std::string corner;
      normal_of_vertex.resize(mesh.vertices.size(), -1);
      while (words >> corner) {
        // v, v/t, v//n or v/t/n
        const size_t slash = corner.find('/');
        const int v =
            resolve(parse_index(corner.substr(0, slash), where), mesh.vertices.size(), where);
        const size_t last_slash = corner.rfind('/');
        if (slash != std::string::npos && last_slash + 1 < corner.size() &&
            corner.find('/', slash + 1) != std::string::npos) {
          normal_of_vertex[static_cast<size_t>(v)] =
              resolve(parse_index(corner.substr(last_slash + 1), where), normal_list.size(), where);
        }
        corners.push_back(v);
      }
      if (corners.size() < 3) throw MeshFileError(where + ": a face needs 3 vertices");
      for (size_t k = 1; k + 1 < corners.size(); ++k) {
        mesh.triangles.emplace_back(corners[0], corners[k], corners[k + 1]);
      }
    }
  }
  if (in.bad()) throw MeshFileError(path + ": read failed");
  normal_of_vertex.resize(mesh.vertices.size(), -1);
  bool all_normals = !normal_list.empty();
  for (const int index : normal_of_vertex) all_normals = all_normals && index >= 0;
  if (all_normals) {
    for (const int index : normal_of_vertex)
      mesh.normals.push_back(normal_list[static_cast<size_t>(index)]);
  }
  if (colors != nullptr && color_list.size() == mesh.vertices.size()) colors->colors = color_list;
  return mesh;
}

}  // namespace featsense::viewer_export
