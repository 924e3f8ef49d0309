#pragma once
/// One scan as the integrator sees it: rays in the map frame.

#include <cstdint>
#include <vector>

#include "featsense/tsdf/vec3.hpp"

namespace featsense::tsdf {

struct RayBatch {
  /// Ray origins, map frame, metres: one per end point (a deskewed scan: the sensor's
  /// position when each point was taken) or a single one for all.
  std::vector<Vec3> origins_m;
  std::vector<Vec3> endpoints_m;  ///< measured points, map frame, metres
  Vec3 up{0.0f, 0.0f, 1.0f};      ///< the sensor's z axis in the map frame (unit)
  /// Per end point, 0 where the ray must not interpolate vertically (its surface is seen at
  /// a grazing angle, so the band would cross it); empty: every ray may.
  std::vector<uint8_t> interpolate;

  size_t size() const { return endpoints_m.size(); }
  Vec3 origin(size_t i) const { return origins_m.size() == 1 ? origins_m[0] : origins_m[i]; }
  bool may_interpolate(size_t i) const { return interpolate.empty() || interpolate[i] != 0; }
};

/// Throws std::invalid_argument unless there is one origin, or one per end point, and the
/// interpolation flags are absent or one per end point.
void check_ray_batch(const RayBatch& rays);

}  // namespace featsense::tsdf
