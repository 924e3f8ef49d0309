#pragma once
/// One scan as the integrator sees it: rays in the map frame.

#include <vector>

#include "featsense/tsdf/vec3.hpp"

namespace featsense::tsdf {

struct RayBatch {
  /// Ray origins, map frame, metres: one per end point (a deskewed scan: the sensor's
  /// position when each point was taken) or a single one for all.
  std::vector<Vec3> origins_m;
  std::vector<Vec3> endpoints_m;  ///< measured points, map frame, metres
  Vec3 up{0.0f, 0.0f, 1.0f};      ///< the sensor's z axis in the map frame (unit)

  size_t size() const { return endpoints_m.size(); }
  Vec3 origin(size_t i) const { return origins_m.size() == 1 ? origins_m[0] : origins_m[i]; }
};

/// Throws std::invalid_argument unless there is one origin, or one per end point.
void check_ray_batch(const RayBatch& rays);

}  // namespace featsense::tsdf
