#pragma once
/// A triangle mesh (or, without triangles, a point cloud) as plain arrays, with optional
/// per-vertex normals and optional named parts (a wall, a car, foliage) carrying the surface's
/// reflectance, which the LiDAR simulator reads. Target `featsense::mesh_types`: Eigen only,
/// so that libraries that only pass meshes around need not link the meshing library.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace featsense::mesh {

/// A mesh that cannot be used: empty, indices out of range, degenerate.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One named part of a mesh and its surface's material.
struct MeshPart {
  /// The reflectance of a triangle that belongs to no part.
  static constexpr float kDefaultReflectance = 0.5f;

  std::string name;
  float reflectance = kDefaultReflectance;  ///< diffuse (Lambertian) reflectance at the
                                            ///< LiDAR's wavelength, 0..1
};

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;   ///< map frame, metres
  std::vector<Eigen::Vector3i> triangles;  ///< vertex indices, counter-clockwise seen from outside
  std::vector<Eigen::Vector3f> normals;    ///< per vertex, unit length, or empty
  std::vector<uint32_t> triangle_part;     ///< per triangle, an index into parts, or empty
  std::vector<MeshPart> parts;

  bool is_point_cloud() const { return triangles.empty(); }
  bool has_normals() const { return !normals.empty() && normals.size() == vertices.size(); }
  bool has_parts() const {
    return !triangle_part.empty() && triangle_part.size() == triangles.size();
  }
  size_t triangle_count() const { return triangles.size(); }
  /// Reflectance of triangle `t`: that of its part, or MeshPart::kDefaultReflectance when the
  /// mesh has no parts.
  float reflectance(size_t t) const {
    return triangle_part.empty() ? MeshPart::kDefaultReflectance
                                 : parts[triangle_part[t]].reflectance;
  }

  // Building a mesh piece by piece (the simulator's scenes). Each piece adds vertices of its
  // own (nothing is shared with what is there) and one part index per triangle; none adds
  // normals.

  /// Adds a part and returns its index.
  uint32_t add_part(const std::string& name, float reflectance);
  /// A triangle of three new vertices a-b-c (metres, map frame).
  void add_triangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                    uint32_t part);
  /// A planar quad a-b-c-d (in order around its edge) as the two triangles a-b-c and a-c-d.
  void add_quad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                const Eigen::Vector3f& d, uint32_t part);
  /// The six faces of an axis-aligned box with corners lo and hi (metres), facing inwards
  /// (counter-clockwise seen from inside: a room's walls).
  void add_box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, uint32_t part);
  /// A vertical cylinder (side and caps) standing on `base` (metres), `segments` sides, facing
  /// outwards.
  void add_cylinder(const Eigen::Vector3f& base, float radius_m, float height_m, int segments,
                    uint32_t part);
  /// Appends another mesh; its parts become new parts. Normals are kept where both meshes have
  /// them (or this one is empty), dropped otherwise. Throws MeshError when the triangles of
  /// one mesh have parts and those of the other do not.
  void append(const TriangleMesh& other);
  /// Axis-aligned bounds of the vertices (lo, hi), metres; zero when there are none.
  void bounds(Eigen::Vector3f* lo, Eigen::Vector3f* hi) const;
};

/// Throws MeshError when a coordinate is not finite, an index is out of range, normals do not
/// match the vertices, or part indices do not match the triangles or the parts (a
/// reflectance outside 0..1 included); `what` names the mesh in the message.
void validate(const TriangleMesh& mesh, const std::string& what);

/// Sum of the triangles' areas, square metres.
double surface_area_m2(const TriangleMesh& mesh);

/// The triangles `which` (indices into mesh.triangles, in that order) with the vertices they
/// use, renumbered in the order of first use; normals kept where the mesh has them, parts
/// dropped. Where given, `source_vertex` receives each kept vertex's index in `mesh`.
TriangleMesh triangle_subset(const TriangleMesh& mesh, const std::vector<uint32_t>& which,
                             std::vector<uint64_t>* source_vertex = nullptr);

/// The axis-aligned box of triangle `t`'s three vertices, in doubles.
Eigen::AlignedBox3d triangle_bounds(const TriangleMesh& mesh, std::size_t t);

/// The triangles of `mesh` whose bounding box meets `box`, in their order, with the vertices
/// they use in the mesh's order (normals kept, parts dropped). Every vertex inside `box` keeps
/// all of its faces.
TriangleMesh triangles_meeting(const TriangleMesh& mesh, const Eigen::AlignedBox3d& box);

}  // namespace featsense::mesh
