#pragma once
// The CPU's walk through the rest of a ray once it is free space (a FreeWalk that walk_ray
// handed over, ray_walk.hpp): the voxels march_ray would visit, each a free-space candidate
// (+tau), handed to the visitor as bits of 64-voxel words instead of one call per voxel:
// `visit.free_word(word, bits)` for the voxels word * 64 + b, b a set bit, in any order and any
// word more than once (the scan's minimum is the same). The general walk (ray_walk.hpp) keeps some
// twenty values alive per step and the CPU has sixteen registers, so its state lived on the stack;
// this loop keeps only what free space needs: the three next crossings, the place in the
// brick and the word's bits. Inside a brick a step moves the place by a constant, and only a
// step along z starts a new word (a word is 8 x 8 voxels of one z layer); the storage index,
// the map's bounds and the settled flag are looked at where the walk enters a brick.
//
// Exact: the same steps in the same order as the general walk (the lower axis first on
// ties), the same jumps across settled bricks (brick_exit), the same turns.

#include <cstdint>

#include "brick_exit.hpp"
#include "featsense/tsdf/local_map_geometry.hpp"
#include "ray_walk.hpp"

namespace featsense::tsdf::detail {

/// Walks from the current voxel (turn `turn`, inside the map, at the first voxel of a brick the
/// walk enters, not yet visited) to the walk's end, where every voxel is free space. `offset`
/// is the walk's: storage_index() and contains() read it.
template <typename Visit, typename StorageIndex, typename Contains>
inline void walk_free_space_words(int32_t offset[3], int32_t t_next[3], const int32_t t_delta[3],
                                  const int32_t step[3], int32_t turn, int32_t end_turn,
                                  const uint8_t* settled_bricks, const StorageIndex& storage_index,
                                  const Contains& contains, Visit& visit) {
  // The place along each axis from which a step leaves the brick, and what a step inside the
  // brick adds to the place (x, then y, then z, fastest first).
  constexpr int32_t kLast = kBrickSize - 1;
  const int32_t edge_x = step[0] > 0 ? kLast : 0;
  const int32_t edge_y = step[1] > 0 ? kLast : 0;
  const int32_t edge_z = step[2] > 0 ? kLast : 0;
  const int32_t move_y = step[1] * kBrickSize;
  const int32_t move_z = step[2] * kBrickSize * kBrickSize;
  for (;;) {  // a brick at a time
    const auto index = storage_index();
    const auto brick_start = index - (index & (kBrickVoxels - 1));
    if (settled_bricks != nullptr && settled_bricks[brick_start / kBrickVoxels] != 0) {
      // Settled free space: every candidate would be passed by; jump to the next brick.
      const int32_t place[3] = {offset[0] & kLast, offset[1] & kLast, offset[2] & kLast};
      BrickExit exit;
      if (!brick_exit(step, place, t_next, t_delta, exit)) return;
      const int32_t taken = exit.crossed[0] + exit.crossed[1] + exit.crossed[2];
      if (turn + taken >= end_turn) return;
      turn += taken;
      for (int axis = 0; axis < 3; ++axis) {
        offset[axis] += step[axis] * exit.crossed[axis];
        t_next[axis] = exit.t_next[axis];
      }
      if (!contains()) return;  // a walk leaves the map once, for good (its axes are monotonic)
      continue;
    }
    int32_t place = static_cast<int32_t>(index - brick_start);
    int32_t next_x = t_next[0];
    int32_t next_y = t_next[1];
    int32_t next_z = t_next[2];
    uint64_t bits = 0;
    int exit_axis = -1;
    const auto word_of = [&] { return static_cast<size_t>((brick_start + place) >> 6); };
    for (;;) {
      bits |= uint64_t{1} << (place & 63);
      if (++turn >= end_turn) break;
      // The walk's step rule (ray_walk.hpp): the nearest crossing, the lower axis on ties.
      const bool y_first = next_y < next_x;
      const bool along_z = next_z < (y_first ? next_y : next_x);
      if (along_z) {
        next_z += t_delta[2];
        if ((place >> 6) == edge_z) {
          exit_axis = 2;
          break;
        }
        visit.free_word(word_of(), bits);
        bits = 0;
        place += move_z;
      } else if (y_first) {
        next_y += t_delta[1];
        if (((place >> 3) & kLast) == edge_y) {
          exit_axis = 1;
          break;
        }
        place += move_y;
      } else {
        next_x += t_delta[0];
        if ((place & kLast) == edge_x) {
          exit_axis = 0;
          break;
        }
        place += step[0];
      }
    }
    visit.free_word(word_of(), bits);
    if (exit_axis < 0) return;  // the walk's end
    t_next[0] = next_x;
    t_next[1] = next_y;
    t_next[2] = next_z;
    // The voxel the walk left the brick from, then the step out of it.
    offset[0] = (offset[0] & ~kLast) + (place & kLast);
    offset[1] = (offset[1] & ~kLast) + ((place >> 3) & kLast);
    offset[2] = (offset[2] & ~kLast) + (place >> 6);
    offset[exit_axis] += step[exit_axis];
    if (!contains()) return;
  }
}

/// The map as a free-space walk sees it: bricks per axis, and the ring buffer's slot of the
/// map's lowest brick.
struct FreeSpaceMap {
  int32_t bricks[3];
  int32_t lowest_slot[3];

  static FreeSpaceMap of(const LocalMapGeometry& map) {
    const Index3 nb = map.bricks();
    const Index3 lowest = map.wrapped_brick(map.origin);
    return {{nb.x, nb.y, nb.z}, {lowest.x, lowest.y, lowest.z}};
  }
  /// The storage brick of a voxel of the map (offset: global index less the lowest corner).
  int32_t brick_of(const int32_t offset[3]) const {
    int32_t slot[3];
    for (int axis = 0; axis < 3; ++axis) {
      const int32_t s = lowest_slot[axis] + (offset[axis] >> kBrickShift);
      slot[axis] = s >= bricks[axis] ? s - bricks[axis] : s;
    }
    return (slot[2] * bricks[1] + slot[1]) * bricks[0] + slot[0];
  }
  bool contains(const int32_t offset[3]) const {
    for (int axis = 0; axis < 3; ++axis) {
      if (static_cast<uint32_t>(offset[axis]) >= static_cast<uint32_t>(bricks[axis] * kBrickSize)) {
        return false;
      }
    }
    return true;
  }
};

/// Walks a set-aside walk with the scalar loop (walk_free_space_words), settled bricks jumped
/// across: `visit.free_word(word, bits)` for its free space.
template <typename Visit>
void walk_free_space_job(FreeWalk walk, const FreeSpaceMap& map, const uint8_t* settled_bricks,
                         Visit& visit) {
  const auto storage_index = [&] {
    const auto place = [&](int axis) { return walk.offset[axis] & (kBrickSize - 1); };
    return int64_t{map.brick_of(walk.offset)} * kBrickVoxels +
           (place(2) * kBrickSize + place(1)) * kBrickSize + place(0);
  };
  const auto contains = [&] { return map.contains(walk.offset); };
  walk_free_space_words(walk.offset, walk.t_next, walk.t_delta, walk.step, 0, walk.turns,
                        settled_bricks, storage_index, contains, visit);
}

}  // namespace featsense::tsdf::detail
