#pragma once
// The CPU's walk through the rest of a ray once it is free space: the voxels march_ray would
// visit, each a free-space candidate (+tau), handed to the visitor as bits of 64-voxel words
// (free_word) instead of one call per voxel. The general walk (ray_walk.hpp) keeps some twenty
// values alive per step and the CPU has sixteen registers, so its state lived on the stack;
// this loop keeps only what free space needs: the three next crossings, the place in the
// brick and the word's bits. Inside a brick a step moves the place by a constant, and only a
// step along z starts a new word (a word is 8 x 8 voxels of one z layer); the storage index,
// the map's bounds and the settled flag are looked at where the walk enters a brick.
//
// Exact: the same steps in the same order as the general walk (the lower axis first on
// ties), the same jumps across settled bricks (brick_exit), the same turns.

#include <type_traits>

#include "brick_exit.hpp"
#include "featsense/tsdf/local_map_geometry.hpp"

namespace featsense::tsdf::detail {

/// Whether a walk's visitor takes free space as words: `free_word(word, bits)` for the voxels
/// word * 64 + b, b a set bit, each proposing +tau (not interpolated), in any order and any
/// word more than once (the scan's minimum is the same). A visitor says so with
/// `static constexpr bool kTakesFreeWords = true;`.
template <typename Visit, typename = void>
struct TakesFreeWords : std::false_type {};
template <typename Visit>
struct TakesFreeWords<Visit, std::void_t<decltype(Visit::kTakesFreeWords)>>
    : std::bool_constant<Visit::kTakesFreeWords> {};

/// A walk's free space set aside, to be walked later with others (free_space_lanes.hpp): the
/// walk's state at its current voxel (inside the map, not yet visited), from which every voxel
/// up to the walk's end is free space.
struct FreeWalk {
  int32_t offset[3];   ///< the voxel: global index less the map's lowest corner
  int32_t t_next[3];   ///< the next crossing per axis (ticks; INT32_MAX where never stepped)
  int32_t t_delta[3];  ///< ticks between crossings per axis
  int32_t step[3];     ///< -1, 0 or 1 per axis
  int32_t turns;       ///< voxels left to visit, the current one included (>= 1)
};

/// Whether a walk's visitor takes the free space at the end of a walk as a whole:
/// `free_walk(const FreeWalk&)` instead of free_word calls (which it must then make itself,
/// for exactly the voxels walk_free_space_words would hand over, settled bricks aside). A
/// visitor says so with `static constexpr bool kTakesFreeWalks = true;`.
template <typename Visit, typename = void>
struct TakesFreeWalks : std::false_type {};
template <typename Visit>
struct TakesFreeWalks<Visit, std::void_t<decltype(Visit::kTakesFreeWalks)>>
    : std::bool_constant<Visit::kTakesFreeWalks> {};

/// Walks from the current voxel (turn `turn`, inside the map, at the first voxel of a brick the
/// walk enters, not yet visited) to the walk's end, where every voxel is free space. `offset`
/// is the walk's: storage_index() and contains() read it (the general walk's functions).
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

}  // namespace featsense::tsdf::detail
