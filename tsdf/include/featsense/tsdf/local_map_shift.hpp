#pragma once
/// Moving the local map with the sensor: which bricks leave the ring buffer and which enter
/// it when its origin moves (the bricks that stay are not copied at all). Moving the voxels
/// with them, to and from the global store, is storage::ShiftingMap's.

#include <cstdint>
#include <vector>

#include "featsense/tsdf/integrator.hpp"

namespace featsense::tsdf {

/// The global brick coordinates of every brick of the local map, x fastest.
std::vector<Index3> bricks_of(const LocalMapGeometry& geometry);

/// Bricks in `from` but not in `to` (leaving) and in `to` but not in `from` (entering), each
/// in x-fastest order. The two boxes have the same size and differ in their origin.
struct BrickExchange {
  std::vector<Index3> leaving;
  std::vector<Index3> entering;
};
BrickExchange exchanged_bricks(const LocalMapGeometry& from, const LocalMapGeometry& to);

/// The origin of the local map of `geometry`'s size centred on the brick that holds
/// `centre_m` (as centred_geometry() places a new map).
Index3 centred_origin(const LocalMapGeometry& geometry, Vec3 centre_m);

}  // namespace featsense::tsdf
