#pragma once
/// A triangle mesh (or, without triangles, a point cloud) as plain arrays.

#include <Eigen/Core>

#include <stdexcept>
#include <string>
#include <vector>

namespace featsense::mesh {

/// A mesh that cannot be used: empty, indices out of range, degenerate.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;   ///< map frame, metres
  std::vector<Eigen::Vector3i> triangles;  ///< vertex indices, counter-clockwise seen from outside
  std::vector<Eigen::Vector3f> normals;    ///< per vertex, unit length, or empty

  bool is_point_cloud() const { return triangles.empty(); }
  bool has_normals() const { return !normals.empty() && normals.size() == vertices.size(); }
};

/// Throws MeshError when a coordinate is not finite, an index is out of range or normals do not
/// match the vertices;
/// `what` names the mesh in the message.
void validate(const TriangleMesh& mesh, const std::string& what);

/// Sum of the triangles' areas, square metres.
double surface_area_m2(const TriangleMesh& mesh);

}  // namespace featsense::mesh
