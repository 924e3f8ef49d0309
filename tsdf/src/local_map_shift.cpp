#include "featsense/tsdf/local_map_shift.hpp"

namespace featsense::tsdf {
namespace {

/// Calls visit(brick) for every brick of `geometry`, x fastest.
template <typename Visit>
void visit_bricks(const LocalMapGeometry& geometry, const Visit& visit) {
  const Index3 first = {geometry.origin.x / kBrickSize, geometry.origin.y / kBrickSize,
                        geometry.origin.z / kBrickSize};
  const Index3 nb = geometry.bricks();
  for (int32_t z = first.z; z < first.z + nb.z; ++z) {
    for (int32_t y = first.y; y < first.y + nb.y; ++y) {
      for (int32_t x = first.x; x < first.x + nb.x; ++x) visit(Index3{x, y, z});
    }
  }
}

}  // namespace

std::vector<Index3> bricks_of(const LocalMapGeometry& geometry) {
  std::vector<Index3> bricks;
  bricks.reserve(geometry.voxel_count() / kBrickVoxels);
  visit_bricks(geometry, [&](Index3 b) { bricks.push_back(b); });
  return bricks;
}

BrickExchange exchanged_bricks(const LocalMapGeometry& from, const LocalMapGeometry& to) {
  BrickExchange exchange;
  visit_bricks(from, [&](Index3 b) {
    if (!to.contains_brick(b)) exchange.leaving.push_back(b);
  });
  visit_bricks(to, [&](Index3 b) {
    if (!from.contains_brick(b)) exchange.entering.push_back(b);
  });
  return exchange;
}

Index3 centred_origin(const LocalMapGeometry& geometry, Vec3 centre_m) {
  const Index3 centre = geometry.voxel_of(centre_m);
  const Index3 nb = geometry.bricks();
  return {(brick_of(centre.x) - (nb.x - 1) / 2) * kBrickSize,
          (brick_of(centre.y) - (nb.y - 1) / 2) * kBrickSize,
          (brick_of(centre.z) - (nb.z - 1) / 2) * kBrickSize};
}

}  // namespace featsense::tsdf
