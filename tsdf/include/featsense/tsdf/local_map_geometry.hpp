#pragma once
/// Where voxels are: the global voxel grid and the ring-buffer layout of the local map,
/// shared by host and device code.
///
/// The global grid is anchored at the map frame's origin: voxel (i, j, k) covers
/// [i, i+1) x [j, j+1) x [k, k+1) times voxel_size_m, its centre at (i + 0.5) * voxel_size_m.
/// The local map is a box of dim voxels per axis whose lowest corner voxel is `origin`
/// (a global index); both are whole bricks of kBrickSize^3 voxels. Storage is brick by
/// brick, so that a ray, which moves through neighbouring voxels, stays in a few kilobytes
/// of memory instead of striding through the whole volume:
///   brick b = floor(g / 8) per axis, local l = g mod 8,
///   linear(g) = brick_slot(b) * 512 + (l.z * 8 + l.y) * 8 + l.x,
///   brick_slot(b) = wrap(b.x) + nb.x * (wrap(b.y) + nb.y * wrap(b.z)),
/// wrap(a) = a mod nb (non-negative), nb = dim / 8. The bricks form a ring buffer: moving the
/// map by whole bricks only rewrites the slabs that leave and enter it, never the rest.

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

constexpr int32_t kBrickShift = 3;
constexpr int32_t kBrickSize = 1 << kBrickShift;  ///< voxels per brick edge
constexpr int32_t kBrickVoxels = kBrickSize * kBrickSize * kBrickSize;

/// floor(a / kBrickSize) for negative a too.
FEATSENSE_HD_INLINE int32_t brick_of(int32_t a) {
  return (a - (a & (kBrickSize - 1))) / kBrickSize;
}

struct LocalMapGeometry {
  Index3 dim;     ///< voxels per axis: an odd number of bricks (the sensor's brick is central)
  Index3 origin;  ///< global index of the lowest corner voxel (a multiple of kBrickSize)
  float voxel_size_m = 0.064f;

  FEATSENSE_HD_INLINE size_t voxel_count() const {
    return static_cast<size_t>(dim.x) * static_cast<size_t>(dim.y) * static_cast<size_t>(dim.z);
  }
  FEATSENSE_HD_INLINE bool contains(Index3 g) const {
    return g.x >= origin.x && g.x < origin.x + dim.x && g.y >= origin.y && g.y < origin.y + dim.y &&
           g.z >= origin.z && g.z < origin.z + dim.z;
  }
  FEATSENSE_HD_INLINE Index3 bricks() const {
    return {dim.x / kBrickSize, dim.y / kBrickSize, dim.z / kBrickSize};
  }
  /// Storage position from a brick's ring-buffer slot coordinates and a voxel's place in it.
  FEATSENSE_HD_INLINE size_t linear_from(Index3 wrapped_brick, Index3 local) const {
    const Index3 nb = bricks();
    const size_t slot = static_cast<size_t>(wrapped_brick.x) +
                        static_cast<size_t>(nb.x) *
                            (static_cast<size_t>(wrapped_brick.y) +
                             static_cast<size_t>(nb.y) * static_cast<size_t>(wrapped_brick.z));
    return slot * kBrickVoxels +
           static_cast<size_t>((local.z * kBrickSize + local.y) * kBrickSize + local.x);
  }
  /// Ring-buffer slot coordinates of the brick that holds global index g.
  FEATSENSE_HD_INLINE Index3 wrapped_brick(Index3 g) const {
    const Index3 nb = bricks();
    return {wrap_index(brick_of(g.x), nb.x), wrap_index(brick_of(g.y), nb.y),
            wrap_index(brick_of(g.z), nb.z)};
  }
  FEATSENSE_HD_INLINE static Index3 local_in_brick(Index3 g) {
    return {g.x & (kBrickSize - 1), g.y & (kBrickSize - 1), g.z & (kBrickSize - 1)};
  }
  /// Storage position of global index g (which must be contained).
  FEATSENSE_HD_INLINE size_t linear(Index3 g) const {
    return linear_from(wrapped_brick(g), local_in_brick(g));
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
  /// The global voxel index of brick b's lowest corner voxel.
  FEATSENSE_HD_INLINE static Index3 first_voxel_of_brick(Index3 b) {
    return {b.x * kBrickSize, b.y * kBrickSize, b.z * kBrickSize};
  }
  FEATSENSE_HD_INLINE bool contains_brick(Index3 b) const {
    return contains(first_voxel_of_brick(b));
  }
  /// Storage position of the first voxel of brick b (which must be contained); the brick's
  /// kBrickVoxels voxels follow it in brick order.
  FEATSENSE_HD_INLINE size_t brick_offset(Index3 b) const {
    return linear(first_voxel_of_brick(b));
  }
  /// The voxel of map-frame point p when p lies inside the local map; false for points
  /// outside it and for NaN. Points from outside must be checked in metres first: voxel
  /// indices are 32-bit, and a far-away point would overflow them.
  FEATSENSE_HD_INLINE bool voxel_in_map(Vec3 p, Index3& voxel) const {
    const Vec3 lo = min_corner();
    const Vec3 hi = max_corner();
    if (!(p.x >= lo.x && p.x < hi.x && p.y >= lo.y && p.y < hi.y && p.z >= lo.z && p.z < hi.z)) {
      return false;
    }
    voxel = voxel_of(p);
    return contains(voxel);
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
