#pragma once
/// Nearest point on a triangle mesh (exact, CGAL's AABB tree) or of a point cloud (k-d tree).
/// CGAL stays inside closest_point_query.cpp.

#include <Eigen/Core>

#include <memory>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh::internal {

struct ClosestPoint {
  Eigen::Vector3d point;   ///< on the surface (or the nearest cloud point), metres
  Eigen::Vector3d normal;  ///< of the nearest triangle or point; zero if none is known
  double distance_m = 0.0;
};

class ClosestPointQuery {
 public:
  /// Triangles of zero area are skipped; a mesh without triangles is queried as a cloud.
  /// Throws MeshError when nothing is left to query.
  explicit ClosestPointQuery(const TriangleMesh& mesh);
  ~ClosestPointQuery();
  ClosestPointQuery(const ClosestPointQuery&) = delete;
  ClosestPointQuery& operator=(const ClosestPointQuery&) = delete;

  /// Thread-safe.
  ClosestPoint closest(const Eigen::Vector3d& query) const;
  bool has_normals() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace featsense::mesh::internal
