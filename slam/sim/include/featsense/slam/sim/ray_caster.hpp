#pragma once
/// Ray casting against a triangle mesh (Embree behind this interface).

#include <Eigen/Core>

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::slam {

/// A ray: origin (map frame, metres), unit direction, and the farthest distance looked at.
struct Ray {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Vector3f direction = Eigen::Vector3f::UnitX();
  float max_distance_m = std::numeric_limits<float>::infinity();
};

/// Where a ray met the mesh: distance along the ray (metres), the triangle, and the
/// triangle's unit normal (map frame, facing the ray's origin). triangle < 0 for a miss.
struct RayHit {
  float distance_m = 0.0f;
  int32_t triangle = -1;
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();
  bool hit() const { return triangle >= 0; }
};

class RayCaster {
 public:
  /// Builds the acceleration structure over `mesh` (copied). Throws std::runtime_error when
  /// the ray tracer cannot be set up.
  explicit RayCaster(const mesh::TriangleMesh& mesh);
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  /// The nearest hit of each ray; `hits` is resized to rays.size(). Runs the rays in
  /// parallel; the result does not depend on the thread count.
  void intersect(const std::vector<Ray>& rays, std::vector<RayHit>* hits) const;
  /// One ray (thread-safe).
  RayHit intersect(const Ray& ray) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace featsense::slam
