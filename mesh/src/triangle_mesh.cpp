#include "featsense/mesh/triangle_mesh.hpp"

#include <Eigen/Geometry>

#include <cmath>

namespace featsense::mesh {

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
  if (!triangles.empty() && !other.triangles.empty() &&
      triangle_part.empty() != other.triangle_part.empty()) {
    throw MeshError("cannot append a mesh: the triangles of only one of the two have parts");
  }
  if (vertices.empty()) {
    normals = other.normals;
  } else if (has_normals() && other.has_normals()) {
    normals.insert(normals.end(), other.normals.begin(), other.normals.end());
  } else {
    normals.clear();
  }
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
  if (!mesh.triangle_part.empty() && mesh.triangle_part.size() != mesh.triangles.size()) {
    throw MeshError(what + ": " + std::to_string(mesh.triangle_part.size()) + " part indices for " +
                    std::to_string(mesh.triangles.size()) + " triangles");
  }
  for (size_t t = 0; t < mesh.triangle_part.size(); ++t) {
    if (mesh.triangle_part[t] >= mesh.parts.size()) {
      throw MeshError(what + ": triangle " + std::to_string(t) + " belongs to part " +
                      std::to_string(mesh.triangle_part[t]) + " of " +
                      std::to_string(mesh.parts.size()));
    }
  }
  for (const MeshPart& part : mesh.parts) {
    if (!(part.reflectance >= 0.0f && part.reflectance <= 1.0f)) {
      throw MeshError(what + ": part '" + part.name + "' has the reflectance " +
                      std::to_string(part.reflectance) + ", not one in 0..1");
    }
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

TriangleMesh triangle_subset(const TriangleMesh& mesh, const std::vector<uint32_t>& which,
                             std::vector<uint64_t>* source_vertex) {
  TriangleMesh out;
  std::vector<int> index(mesh.vertices.size(), -1);
  const bool normals = mesh.has_normals();
  for (uint32_t t : which) {
    Eigen::Vector3i kept;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<size_t>(mesh.triangles[t][k]);
      if (index[v] < 0) {
        index[v] = static_cast<int>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[v]);
        if (normals) out.normals.push_back(mesh.normals[v]);
        if (source_vertex) source_vertex->push_back(v);
      }
      kept[k] = index[v];
    }
    out.triangles.push_back(kept);
  }
  return out;
}

Eigen::AlignedBox3d triangle_bounds(const TriangleMesh& mesh, std::size_t t) {
  Eigen::AlignedBox3d box;
  box.setEmpty();
  for (int k = 0; k < 3; ++k)
    box.extend(mesh.vertices[static_cast<std::size_t>(mesh.triangles[t][k])].cast<double>());
  return box;
}

TriangleMesh triangles_meeting(const TriangleMesh& mesh, const Eigen::AlignedBox3d& box) {
  // The vertices stay in the mesh's order: where copies of a position differ (a split
  // non-manifold vertex's normals), welding keeps the first copy, the one the whole mesh
  // would keep.
  std::vector<int> index(mesh.vertices.size(), -1);
  std::vector<std::size_t> meeting;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!triangle_bounds(mesh, t).intersects(box)) continue;
    meeting.push_back(t);
    for (int k = 0; k < 3; ++k) index[static_cast<std::size_t>(mesh.triangles[t][k])] = 0;
  }
  TriangleMesh out;
  const bool normals = mesh.has_normals();
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (index[v] < 0) continue;
    index[v] = static_cast<int>(out.vertices.size());
    out.vertices.push_back(mesh.vertices[v]);
    if (normals) out.normals.push_back(mesh.normals[v]);
  }
  for (const std::size_t t : meeting) {
    const Eigen::Vector3i& corners = mesh.triangles[t];
    out.triangles.emplace_back(index[static_cast<std::size_t>(corners[0])],
                               index[static_cast<std::size_t>(corners[1])],
                               index[static_cast<std::size_t>(corners[2])]);
  }
  return out;
}

}  // namespace featsense::mesh
