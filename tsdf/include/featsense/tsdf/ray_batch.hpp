#pragma once
/// One scan as the integrator sees it: rays in the map frame. Its arrays live in host_memory
/// (page-locked once a CUDA integrator exists), which the GPU reads without a staging copy.

#include <cstdint>
#include <vector>

#include "featsense/tsdf/host_memory.hpp"
#include "featsense/tsdf/vec3.hpp"

namespace featsense::tsdf {

/// A carving level at which a ray carves free space all the way to the sensor.
constexpr uint8_t kFullCarvingLevel = 16;

struct RayBatch {
  /// Ray origins, map frame, metres: one per end point (a deskewed scan: the sensor's
  /// position when each point was taken) or a single one for all.
  HostVector<Vec3> origins_m;
  HostVector<Vec3> endpoints_m;  ///< measured points, map frame, metres
  Vec3 up{0.0f, 0.0f, 1.0f};     ///< the sensor's z axis in the map frame (unit)
  /// Per end point, 0 where the ray must not interpolate vertically (its surface is seen at
  /// a grazing angle, so the band would cross it); empty: every ray may.
  HostVector<uint8_t> interpolate;
  /// Per end point, the ray's place in the lattice of sparse carving
  /// (TsdfSettings::dense_range_m): the largest L with its beam and column both multiples of
  /// 2^L (kFullCarvingLevel and above: carves all the way); empty: every ray carves all the way.
  HostVector<uint8_t> carving_level;

  size_t size() const { return endpoints_m.size(); }
  Vec3 origin(size_t i) const { return origins_m.size() == 1 ? origins_m[0] : origins_m[i]; }
  bool may_interpolate(size_t i) const { return interpolate.empty() || interpolate[i] != 0; }
  uint8_t carving_level_of(size_t i) const {
    return carving_level.empty() ? kFullCarvingLevel : carving_level[i];
  }
};

/// Throws std::invalid_argument unless there is one origin, or one per end point, and the
/// interpolation flags and carving levels are each absent or one per end point.
void check_ray_batch(const RayBatch& rays);

}  // namespace featsense::tsdf
