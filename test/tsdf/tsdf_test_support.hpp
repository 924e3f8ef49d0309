#pragma once
// Reading values out of an integrator's map in metres, for the TSDF tests.

#include <functional>
#include <memory>
#include <vector>

#include "featsense/tsdf/integrator.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::tsdf::test {

/// Settings for small, fast test maps: 0.1 m voxels, tau 0.4 m, 16 x 16 x 8 m.
inline TsdfSettings small_map_settings() {
  TsdfSettings s;
  s.voxel_size_m = 0.1f;
  s.truncation_m = 0.4f;
  s.max_weight = 10.0f;
  s.map_size_m = {16.0f, 16.0f, 8.0f};
  s.interpolation_slope = 0.0f;
  return s;
}

struct ObservedVoxel {
  Index3 index;
  Vec3 centre_m;
  float distance_m;  ///< the stored value in metres
  float weight;      ///< the stored weight (1.0 = one full measurement)
};

/// Every brick of the local map, by global brick coordinate (for read_bricks / write_bricks).
inline std::vector<Index3> all_bricks(const LocalMapGeometry& g) {
  std::vector<Index3> bricks;
  for (int32_t z = 0; z < g.dim.z; z += kBrickSize) {
    for (int32_t y = 0; y < g.dim.y; y += kBrickSize) {
      for (int32_t x = 0; x < g.dim.x; x += kBrickSize) {
        bricks.push_back({(g.origin.x + x) / kBrickSize, (g.origin.y + y) / kBrickSize,
                          (g.origin.z + z) / kBrickSize});
      }
    }
  }
  return bricks;
}

/// Writes every brick of `from` into `to` (a map of the same geometry), as a shift loads
/// bricks from the store.
inline void copy_all_bricks(const Integrator& from, Integrator& to) {
  const std::vector<Index3> bricks = all_bricks(from.geometry());
  std::vector<uint32_t> voxels;
  from.read_bricks(bricks, voxels);
  to.write_bricks(bricks, voxels);
}

/// Calls f for every voxel of the map (observed or not).
inline void for_each_voxel(const Integrator& integrator, float truncation_m,
                           const std::function<void(const ObservedVoxel&)>& f) {
  const std::vector<uint32_t> voxels = integrator.download();
  const LocalMapGeometry& g = integrator.geometry();
  for (int32_t z = 0; z < g.dim.z; ++z) {
    for (int32_t y = 0; y < g.dim.y; ++y) {
      for (int32_t x = 0; x < g.dim.x; ++x) {
        const Index3 index{g.origin.x + x, g.origin.y + y, g.origin.z + z};
        const Voxel v = unpack(voxels[g.linear(index)]);
        f({index, g.centre_of(index), fixed_to_distance(v.value, truncation_m),
           fixed_to_weight(v.weight)});
      }
    }
  }
}

}  // namespace featsense::tsdf::test
