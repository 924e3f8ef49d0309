#include "featsense/slam/sim/triangle_mesh.hpp"

#include <cmath>

namespace featsense::slam {

uint32_t TriangleMesh::add_part(const std::string& name, float reflectance) {
  parts.push_back({name, reflectance});
  return static_cast<uint32_t>(parts.size() - 1);
}

void TriangleMesh::add_triangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                                const Eigen::Vector3f& c, uint32_t part) {
  const int first = static_cast<int>(vertices.size());
  vertices.push_back(a);
  vertices.push_back(b);
  vertices.push_back(c);
  triangles.emplace_back(first, first + 1, first + 2);
  triangle_part.push_back(part);
}

void TriangleMesh::add_quad(const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                            const Eigen::Vector3f& c, const Eigen::Vector3f& d, uint32_t part) {
  const int first = static_cast<int>(vertices.size());
  vertices.insert(vertices.end(), {a, b, c, d});
  triangles.emplace_back(first, first + 1, first + 2);
  triangles.emplace_back(first, first + 2, first + 3);
  triangle_part.insert(triangle_part.end(), {part, part});
}

void TriangleMesh::add_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, uint32_t part) {
  const auto corner = [&](int i) {
    return Eigen::Vector3f((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(),
                           (i & 4) ? hi.z() : lo.z());
  };
  // Faces as corner indices around their edges (bit 0: x, bit 1: y, bit 2: z).
  static const int kFaces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                   {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& f : kFaces)
    add_quad(corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3]), part);
}

void TriangleMesh::add_cylinder(const Eigen::Vector3f& base, float radius_m, float height_m,
                                int segments, uint32_t part) {
  const Eigen::Vector3f up(0.0f, 0.0f, height_m);
  for (int i = 0; i < segments; ++i) {
    const float a0 = static_cast<float>(2.0 * M_PI * i / segments);
    const float a1 = static_cast<float>(2.0 * M_PI * (i + 1) / segments);
    const Eigen::Vector3f p0 = base + radius_m * Eigen::Vector3f(std::cos(a0), std::sin(a0), 0);
    const Eigen::Vector3f p1 = base + radius_m * Eigen::Vector3f(std::cos(a1), std::sin(a1), 0);
    add_quad(p0, p1, p1 + up, p0 + up, part);
    add_triangle(base, p1, p0, part);
    add_triangle(base + up, p0 + up, p1 + up, part);
  }
}

void TriangleMesh::append(const TriangleMesh& other) {
  const int vertex_offset = static_cast<int>(vertices.size());
  const uint32_t part_offset = static_cast<uint32_t>(parts.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const Eigen::Vector3i& t : other.triangles)
    triangles.push_back(t + Eigen::Vector3i::Constant(vertex_offset));
  for (uint32_t p : other.triangle_part) triangle_part.push_back(p + part_offset);
  parts.insert(parts.end(), other.parts.begin(), other.parts.end());
}

void TriangleMesh::bounds(Eigen::Vector3f* lo, Eigen::Vector3f* hi) const {
  if (vertices.empty()) {
    *lo = *hi = Eigen::Vector3f::Zero();
    return;
  }
  *lo = *hi = vertices.front();
  for (const Eigen::Vector3f& v : vertices) {
    *lo = lo->cwiseMin(v);
    *hi = hi->cwiseMax(v);
  }
}

}  // namespace featsense::slam
