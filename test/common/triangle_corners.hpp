#pragma once
// A mesh's surface independent of its vertex numbering, to compare two meshes triangle for
// triangle: each triangle as its three corners' positions, starting at the smallest (its
// winding kept), the list sorted.

#include <algorithm>
#include <array>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::test {

inline std::vector<std::array<float, 9>> triangle_corners(const mesh::TriangleMesh& m) {
  std::vector<std::array<float, 9>> corners;
  corners.reserve(m.triangles.size());
  for (const Eigen::Vector3i& t : m.triangles) {
    std::array<std::array<float, 3>, 3> c;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& v = m.vertices[static_cast<size_t>(t[k])];
      c[static_cast<size_t>(k)] = {v.x(), v.y(), v.z()};
    }
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    corners.push_back(
        {c[0][0], c[0][1], c[0][2], c[1][0], c[1][1], c[1][2], c[2][0], c[2][1], c[2][2]});
  }
  std::sort(corners.begin(), corners.end());
  return corners;
}

/// The parts as one mesh (vertices not welded).
inline mesh::TriangleMesh append_mesh(mesh::TriangleMesh whole, const mesh::TriangleMesh& part) {
  const int first = static_cast<int>(whole.vertices.size());
  whole.vertices.insert(whole.vertices.end(), part.vertices.begin(), part.vertices.end());
  for (const Eigen::Vector3i& t : part.triangles)
    whole.triangles.push_back(t + Eigen::Vector3i::Constant(first));
  return whole;
}

}  // namespace featsense::test
