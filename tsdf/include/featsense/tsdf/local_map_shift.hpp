#pragma once
/// Moving the local map with the sensor: the bricks that leave the ring buffer go to a sink
/// (the global store), the bricks that enter come from a source (the store, or empty), and
/// the bricks that stay are not copied at all.

#include <cstdint>
#include <functional>
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

/// Gives the voxels of `bricks` (brick order, kBrickVoxels each, as Integrator::read_bricks).
using BrickSource =
    std::function<void(const std::vector<Index3>& bricks, std::vector<uint32_t>& voxels)>;
/// Takes the voxels of `bricks` leaving the local map.
using BrickSink =
    std::function<void(const std::vector<Index3>& bricks, const std::vector<uint32_t>& voxels)>;

struct ShiftStats {
  size_t bricks_left = 0;
  size_t bricks_entered = 0;
};

/// The voxels of the leaving and the entering bricks. A slab of a 40 x 40 x 15 m map is
/// tens of megabytes: kept from one shift to the next, its memory is not faulted in and
/// zeroed again each time.
struct ShiftBuffers {
  std::vector<uint32_t> leaving;
  std::vector<uint32_t> entering;
};

/// Moves `map` so that its lowest corner is `new_origin`: the leaving bricks are read and
/// handed to `spill`, the entering ones are filled from `load`. The map is consistent
/// whenever this returns or throws before set_origin (spill runs last, so a failing sink
/// leaves the map moved but complete, and the caller may retry the spill).
ShiftStats shift_local_map(Integrator& map, Index3 new_origin, const BrickSource& load,
                           const BrickSink& spill, ShiftBuffers& buffers);
ShiftStats shift_local_map(Integrator& map, Index3 new_origin, const BrickSource& load,
                           const BrickSink& spill);

/// The origin of the local map of `geometry`'s size centred on the brick that holds
/// `centre_m` (as centred_geometry() places a new map).
Index3 centred_origin(const LocalMapGeometry& geometry, Vec3 centre_m);

}  // namespace featsense::tsdf
