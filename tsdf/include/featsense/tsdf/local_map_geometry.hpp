#pragma once
/// Where voxels are: the global voxel grid and the ring-buffer layout of the local map,
/// shared by host and device code.
///
/// The global grid is anchored at the map frame's origin: voxel (i, j, k) covers
/// [i, i+1) x [j, j+1) x [k, k+1) times voxel_size_m, its centre at (i + 0.5) * voxel_size_m.
/// The local map is a box of dim voxels per axis whose lowest corner voxel is `origin`
/// (a global index). It is stored as a ring buffer: global index g lives at
/// wrap(g.x) + dim.x * (wrap(g.y) + dim.y * wrap(g.z)), wrap(a) = a mod dim (non-negative),
/// so moving the map only rewrites the slabs that leave and enter it, never the rest.

#include <cstddef>
#include <cstdint>

#include "featsense/tsdf/host_device.hpp"
#include "featsense/tsdf/vec3.hpp"

namespace featsense::tsdf {

FEATSENSE_HD_INLINE int32_t floor_to_int(float x) { return static_cast<int32_t>(floorf(x)); }

FEATSENSE_HD_INLINE int32_t wrap_index(int32_t a, int32_t n) {
  const int32_t r = a % n;
  return r < 0 ? r + n : r;
}

struct LocalMapGeometry {
  Index3 dim;     ///< voxels per axis (odd, so the sensor sits in the centre voxel)
  Index3 origin;  ///< global index of the lowest corner voxel
  float voxel_size_m = 0.064f;

  FEATSENSE_HD_INLINE size_t voxel_count() const {
    return static_cast<size_t>(dim.x) * static_cast<size_t>(dim.y) * static_cast<size_t>(dim.z);
  }
  FEATSENSE_HD_INLINE bool contains(Index3 g) const {
    return g.x >= origin.x && g.x < origin.x + dim.x && g.y >= origin.y && g.y < origin.y + dim.y &&
           g.z >= origin.z && g.z < origin.z + dim.z;
  }
  /// Storage position of global index g (which must be contained).
  FEATSENSE_HD_INLINE size_t linear(Index3 g) const {
    return static_cast<size_t>(wrap_index(g.x, dim.x)) +
           static_cast<size_t>(dim.x) *
               (static_cast<size_t>(wrap_index(g.y, dim.y)) +
                static_cast<size_t>(dim.y) * static_cast<size_t>(wrap_index(g.z, dim.z)));
  }
  /// The global voxel that holds map-frame point p (metres).
  FEATSENSE_HD_INLINE Index3 voxel_of(Vec3 p) const {
    const float inv = 1.0f / voxel_size_m;
    return {floor_to_int(p.x * inv), floor_to_int(p.y * inv), floor_to_int(p.z * inv)};
  }
  FEATSENSE_HD_INLINE Vec3 centre_of(Index3 g) const {
    return {(static_cast<float>(g.x) + 0.5f) * voxel_size_m,
            (static_cast<float>(g.y) + 0.5f) * voxel_size_m,
            (static_cast<float>(g.z) + 0.5f) * voxel_size_m};
  }
  /// Lowest and highest corner of the local map, metres.
  FEATSENSE_HD_INLINE Vec3 min_corner() const {
    return {static_cast<float>(origin.x) * voxel_size_m,
            static_cast<float>(origin.y) * voxel_size_m,
            static_cast<float>(origin.z) * voxel_size_m};
  }
  FEATSENSE_HD_INLINE Vec3 max_corner() const {
    return {static_cast<float>(origin.x + dim.x) * voxel_size_m,
            static_cast<float>(origin.y + dim.y) * voxel_size_m,
            static_cast<float>(origin.z + dim.z) * voxel_size_m};
  }
};

}  // namespace featsense::tsdf
