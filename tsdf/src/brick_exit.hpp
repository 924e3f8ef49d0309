#pragma once
// Where a walk leaves the brick it is in, computed without stepping through its voxels: both
// backends' walks jump across bricks of settled free space with it (ray_walk.hpp).

#include "featsense/tsdf/host_device.hpp"
#include "featsense/tsdf/local_map_geometry.hpp"
#include "ray_marcher.hpp"

namespace featsense::tsdf::detail {

/// Where a walk leaves the brick it is in, and the traversal state it arrives with there.
struct BrickExit {
  int axis;            ///< the axis whose crossing leaves the brick
  int32_t t;           ///< the walk's t at that crossing (ticks)
  int32_t crossed[3];  ///< face crossings per axis up to and including it
  int32_t t_next[3];   ///< the next crossing per axis after them
};

/// The exit of the walk from its current brick (`local`: its place in the brick), computed
/// without stepping through the voxels: crossings of voxel faces come in the order of their
/// t, the lower axis first on ties (the rule of the walk's step), and an axis's crossings are
/// t_next + j * t_delta in exact integer ticks (WalkClock), so the state is exactly the one that
/// stepping voxel by voxel reaches. A brick all of whose voxels would pass every candidate by
/// can so be crossed in one jump. False where no axis is stepped along.
/// Nothing depends on an earlier result but the exit itself, and no loop's length on the
/// lane, so on the GPU a warp's jumping lanes run one short code path together.
FEATSENSE_HD_INLINE bool brick_exit(const int32_t step[3], const int32_t local[3],
                                    const int32_t t_next[3], const int32_t t_delta[3],
                                    BrickExit& exit) {
  // Arrays are indexed only by the unrolled loops' constants, so that they live in registers.
  // Ticks stay below 2^31: t_next <= 2 kBeyondWalk and t_delta <= kBeyondWalk = 2^27 + 1.
  static_assert(int64_t{2 + kBrickSize} * kBeyondWalk < int64_t{1} << 31, "ticks overflow");
  int32_t to_leave[3] = {0, 0, 0};  // crossings along the axis up to the one out of the brick
  exit.axis = -1;
  exit.t = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (step[axis] == 0) continue;
    to_leave[axis] = step[axis] > 0 ? kBrickSize - local[axis] : local[axis] + 1;
    const int32_t t_out = t_next[axis] + (to_leave[axis] - 1) * t_delta[axis];
    if (exit.axis < 0 || t_out < exit.t) {
      exit.axis = axis;
      exit.t = t_out;
    }
  }
  if (exit.axis < 0) return false;
  for (int axis = 0; axis < 3; ++axis) {
    int32_t crossed = 0;
    if (axis == exit.axis) {
      crossed = to_leave[axis];
    } else if (step[axis] != 0) {
      // The crossings before the exit (at a tie, those of a lower axis): fewer than
      // to_leave[axis], else this axis would leave first, so fewer than kBrickSize.
      const int32_t before = exit.t + (axis < exit.axis ? 1 : 0);
      for (int32_t j = 0; j < kBrickSize - 1; ++j) {
        crossed += t_next[axis] + j * t_delta[axis] < before ? 1 : 0;
      }
    }
    exit.crossed[axis] = crossed;
    exit.t_next[axis] = t_next[axis] + crossed * t_delta[axis];
  }
  return true;
}

}  // namespace featsense::tsdf::detail
