#pragma once
// Analytic reference meshes for the comparison tests.

#include <Eigen/Geometry>

#include <cmath>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::test {

/// The square [x0, x1] x [y0, y1] at height z, split into n x n cells of two triangles, normal +z.
inline mesh::TriangleMesh grid_plane(float x0, float x1, float y0, float y1, float z, int n) {
  mesh::TriangleMesh m;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      m.vertices.emplace_back(x0 + (x1 - x0) * static_cast<float>(i) / static_cast<float>(n),
                              y0 + (y1 - y0) * static_cast<float>(j) / static_cast<float>(n), z);
    }
  }
  auto at = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      m.triangles.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      m.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return m;
}

/// The axis-aligned box [-h, h]^3 as 12 triangles, normals outwards.
inline mesh::TriangleMesh box_mesh(float h) {
  mesh::TriangleMesh m;
  for (int k = 0; k < 8; ++k) {
    m.vertices.emplace_back((k & 1) ? h : -h, (k & 2) ? h : -h, (k & 4) ? h : -h);
  }
  // Each face as a quad a b c d, counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.emplace_back(q[0], q[1], q[2]);
    m.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return m;
}

/// An icosphere of radius r (subdivided `levels` times), normals outwards.
inline mesh::TriangleMesh icosphere(float r, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Eigen::Vector3i> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int level = 0; level < levels; ++level) {
    std::vector<Eigen::Vector3i> next;
    for (const auto& tri : f) {
      int mid[3];
      for (int k = 0; k < 3; ++k) {
        v.push_back((v[static_cast<size_t>(tri[k])] + v[static_cast<size_t>(tri[(k + 1) % 3])])
                        .normalized());
        mid[k] = static_cast<int>(v.size()) - 1;
      }
      next.emplace_back(tri[0], mid[0], mid[2]);
      next.emplace_back(tri[1], mid[1], mid[0]);
      next.emplace_back(tri[2], mid[2], mid[1]);
      next.emplace_back(mid[0], mid[1], mid[2]);
    }
    f = next;
  }
  mesh::TriangleMesh m;
  for (const auto& p : v) m.vertices.push_back((r * p).cast<float>());
  m.triangles = f;
  return m;
}

}  // namespace featsense::test
