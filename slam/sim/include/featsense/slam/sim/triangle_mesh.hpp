#pragma once
/// A triangle soup with a material per part: what the simulator casts rays against.

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace featsense::slam {

/// One named part of a mesh (a wall, a car, foliage) and its surface's material.
struct MeshPart {
  std::string name;
  float reflectance = 0.5f;  ///< diffuse (Lambertian) reflectance at the sensor's wavelength, 0..1
};

/// Vertices (map frame, metres, Z up), triangles as vertex indices, and per triangle the
/// index of the part it belongs to.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<uint32_t> triangle_part;  ///< one per triangle, index into parts
  std::vector<MeshPart> parts;

  size_t triangle_count() const { return triangles.size(); }
  /// Adds a part and returns its index.
  uint32_t add_part(const std::string& name, float reflectance);
  /// Adds a triangle of three new vertices (metres, map frame).
  void add_triangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                    uint32_t part);
  /// A planar quad a-b-c-d (in order around its edge) as two triangles.
  void add_quad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                const Eigen::Vector3f& d, uint32_t part);
  /// The six faces of an axis-aligned box with corners lo and hi (metres).
  void add_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, uint32_t part);
  /// A vertical cylinder (side and caps) standing on `base` (metres), `segments` sides.
  void add_cylinder(const Eigen::Vector3f& base, float radius_m, float height_m, int segments,
                    uint32_t part);
  /// Appends another mesh (its parts become new parts).
  void append(const TriangleMesh& other);
  /// Axis-aligned bounds of the vertices (lo, hi), metres; zero when empty.
  void bounds(Eigen::Vector3f* lo, Eigen::Vector3f* hi) const;
  /// Reflectance of the part of triangle `t`.
  float reflectance(size_t t) const { return parts[triangle_part[t]].reflectance; }
};

}  // namespace featsense::slam
