#pragma once
// The walk of one ray that both backends run (the CUDA kernels compile it too: no CPU-only
// code here): exactly the candidates of detail::march_ray (ray_marcher.hpp, the plain
// statement of the rule, which the tests use as the reference), computed with less work per
// voxel. The float operations that decide which voxels are visited and what they get are the
// same ones in the same order, so the results are bit for bit the same
// (test_cpu_integrator_exact checks it against march_ray itself); only bookkeeping is cheaper:
// - the storage index and the map-bounds test follow the traversal incrementally instead of
//   being recomputed from the global index at every voxel, across brick faces too;
// - the projective distance (march_ray's own expression) is computed only where a voxel may
//   lie in the truncation band, not from where the rest of the walk is free space
//   (free_space_from);
// - free space (d >= tau) needs no division: d / tau >= 1 there, so the clamped value is
//   exactly kValueScale, and there is no interpolation;
// - where the rest of the walk is free space, a brick of settled free space (voxel.hpp,
//   settled_free_voxel), where every candidate would be passed by, is crossed in one jump
//   (brick_exit), which computes the state that stepping through it would reach;
// - on the CPU, a visitor may take the free space at the end of the walk whole (FreeWalk),
//   which the CPU integrator walks with loops that know it is all free space (cpu_fast/);
// - every array is indexed by constants only (one code path per stepped axis), so the
//   traversal state stays in registers, on the GPU too (no local memory).

#include <type_traits>

#include "brick_exit.hpp"
#include "ray_marcher.hpp"

namespace featsense::tsdf::detail {

/// The walk's t from which every voxel it enters is free space: a voxel's centre lies within
/// 0.87 voxels of the ray where the ray crosses it, so from here on its distance to the end
/// point is at least tau. t1: the ray parameter where the walk starts.
FEATSENSE_HD_INLINE float free_space_from(float t1, float range, float truncation_m,
                                          float voxel_size_m) {
  return truncation_m + voxel_size_m + t1 - range;
}

/// The storage index a walk follows, and hands to its visitor: 32 bits on the GPU, where
/// 64-bit arithmetic takes two instructions for one (the CUDA backend holds at most 2^32
/// voxels a volume, checked where it is made); 64 on the CPU.
#ifdef __CUDA_ARCH__
using WalkIndex = uint32_t;
#else
using WalkIndex = int64_t;
#endif

/// One of `count` parts of a walk, which together make the whole walk: part k takes the
/// voxels entered from k / count of the walk's ticks on (up to the next part's). A walk's state
/// at any tick follows from its crossings (first + j * delta, exact), so a part starts where
/// the whole walk would be there, and visits what it would visit. The GPU walks long rays in
/// parts, so that its multiprocessors share the work evenly.
struct WalkPart {
  int32_t index = 0;
  int32_t count = 1;
};

/// The free space at the end of a walk, handed to a visitor whole (CPU only): the walk's state
/// at its current voxel (inside the map, not yet visited), from which every voxel up to the
/// walk's end is free space (+tau, measured, each).
struct FreeWalk {
  int32_t offset[3];   ///< the voxel: global index less the map's lowest corner
  int32_t t_next[3];   ///< the next crossing per axis (ticks; INT32_MAX where never stepped)
  int32_t t_delta[3];  ///< ticks between crossings per axis
  int32_t step[3];     ///< -1, 0 or 1 per axis
  int32_t turns;       ///< voxels left to visit, the current one included (>= 1)
};

/// Whether a walk's visitor takes the free space at the end of a walk whole:
/// `free_walk(const FreeWalk&)` instead of a call per voxel, for it to propose +tau for exactly
/// the voxels the rest of the walk would visit (those of settled bricks may be left out: they
/// pass +tau by). A visitor says so with `static constexpr bool kTakesFreeWalks = true;`.
/// Only the CPU's walk hands free space over; the GPU's visits every voxel.
template <typename Visit, typename = void>
struct TakesFreeWalks : std::false_type {};
template <typename Visit>
struct TakesFreeWalks<Visit, std::void_t<decltype(Visit::kTakesFreeWalks)>>
    : std::bool_constant<Visit::kTakesFreeWalks> {};

/// Calls visit(linear_index, value_fixed, interpolated) for every candidate march_ray would
/// propose for this ray, in the same order, except the free-space candidates of the bricks
/// that `settled_bricks` (nonzero per brick slot, or null) names as settled free space; only
/// those of `part` of the walk.
template <typename Visit>
FEATSENSE_HD_INLINE void walk_ray(Vec3 origin, Vec3 endpoint, const LocalMapGeometry& map,
                                  const RayMarchParams& params, Visit&& visit,
                                  const uint8_t* settled_bricks = nullptr, WalkPart part = {}) {
  RaySetup ray;
  if (!setup_ray(origin, endpoint, map, params, ray)) return;
  const float range = ray.range;
  const Vec3 dir = ray.dir;
  const int32_t walk_end_ticks = ray.end_ticks;
  const Index3 nb = map.bricks();
  const Index3 lowest_slot = map.wrapped_brick(map.origin);

  int32_t step[3] = {};
  int32_t t_next[3] = {};  // ticks (WalkClock)
  int32_t t_delta[3] = {};
  int32_t offset[3] = {};  // global index less the map's lowest corner: inside when in [0, dim)
  int32_t dim[3] = {};     // voxels per axis, of the map and of its ring buffer
  // Where offset 0 lies in the ring buffer: the slot of the map's lowest brick * kBrickSize.
  int32_t base[3] = {};
  int32_t crossings = 0;  // face crossings up to the walk's end
  for (int axis = 0; axis < 3; ++axis) {
    const AxisCrossings c = ray.axes[axis];
    step[axis] = c.step;
    // An axis the walk runs parallel to is never stepped along: its crossing never comes.
    t_next[axis] = c.step != 0 ? c.first : INT32_MAX;
    t_delta[axis] = c.delta;
    if (c.step != 0 && c.first <= walk_end_ticks) {
      crossings += (walk_end_ticks - c.first) / c.delta + 1;
    }
    offset[axis] = component(ray.voxel, axis) - component(map.origin, axis);
    dim[axis] = component(map.dim, axis);
    base[axis] = component(lowest_slot, axis) * kBrickSize;
  }
  // The walk's turns: its first voxel, then one a crossing up to its end (crossings come in the
  // order of their t, so counting them ends the walk where t passes the end). Bounded by the
  // voxels a segment can cross, so rounding can never loop forever.
  const int32_t max_steps = map.dim.x + map.dim.y + map.dim.z + 3;
  const int32_t turns = crossings + 1 < max_steps ? crossings + 1 : max_steps;

  // The part's turns: from the first whose voxel is entered at its first tick, up to the next
  // part's first. Turn i visits the voxel reached by the walk's first i crossings.
  int32_t t = 0;  // the tick of the last crossing, where the current voxel was entered
  int32_t first_turn = 0;
  int32_t end_turn = turns;
  if (part.count > 1) {
    const auto part_start = [&](int32_t k) {
      return static_cast<int32_t>(static_cast<int64_t>(walk_end_ticks) * k / part.count);
    };
    const auto crossings_before = [&](int axis, int32_t tick) {  // those with t < tick
      return step[axis] == 0 || tick <= t_next[axis]
                 ? 0
                 : (tick - 1 - t_next[axis]) / t_delta[axis] + 1;
    };
    if (part.index + 1 < part.count) {
      const int32_t end = part_start(part.index + 1);
      const int32_t before =
          crossings_before(0, end) + crossings_before(1, end) + crossings_before(2, end);
      end_turn = before < turns ? before : turns;
    }
    const int32_t begin = part_start(part.index);
    for (int axis = 0; axis < 3; ++axis) {  // the state after the crossings before `begin`
      const int32_t crossed = crossings_before(axis, begin);
      if (crossed == 0) continue;
      const int32_t last = t_next[axis] + (crossed - 1) * t_delta[axis];
      t = last > t ? last : t;
      t_next[axis] = last + t_delta[axis];
      offset[axis] += step[axis] * crossed;
      first_turn += crossed;
    }
    if (first_turn >= end_turn) return;
  }
  // map.linear of the current voxel, from its offset, in WalkIndex arithmetic: a voxel of the
  // map lies at base + offset in the ring buffer, less its length where that passes the end
  // (the map's lowest corner is a whole brick, so the place in the brick is the offset's).
  // Meaningful inside the map only: nothing outside it is visited or loaded.
  const auto storage_index = [&] {
    const auto slot = [&](int axis) {
      const int32_t b = (base[axis] + offset[axis]) >> kBrickShift;
      const int32_t bricks = dim[axis] >> kBrickShift;
      return static_cast<WalkIndex>(b >= bricks ? b - bricks : b);
    };
    const auto place = [&](int axis) {
      return static_cast<WalkIndex>(offset[axis] & (kBrickSize - 1));
    };
    const WalkIndex bricks_x = static_cast<WalkIndex>(dim[0] >> kBrickShift);
    const WalkIndex bricks_y = static_cast<WalkIndex>(dim[1] >> kBrickShift);
    return ((slot(2) * bricks_y + slot(1)) * bricks_x + slot(0)) * kBrickVoxels +
           (place(2) * kBrickSize + place(1)) * kBrickSize + place(0);
  };
  const auto contains = [&] {
    return static_cast<uint32_t>(offset[0]) < static_cast<uint32_t>(dim[0]) &&
           static_cast<uint32_t>(offset[1]) < static_cast<uint32_t>(dim[1]) &&
           static_cast<uint32_t>(offset[2]) < static_cast<uint32_t>(dim[2]);
  };

  // map.linear for a voxel known to lie in the map, without its three divisions: the brick's
  // offset from the map's lowest brick is below the brick count, so wrapping it is one
  // comparison (the map's lowest corner is a whole brick, so the place in the brick is too).
  const auto linear_of_contained = [&](Index3 g) {
    const auto slot = [](int32_t relative, int32_t lowest, int32_t count) {
      const int32_t b = lowest + (relative >> kBrickShift);
      return b >= count ? b - count : b;
    };
    const Index3 r{g.x - map.origin.x, g.y - map.origin.y, g.z - map.origin.z};
    return map.linear_from({slot(r.x, lowest_slot.x, nb.x), slot(r.y, lowest_slot.y, nb.y),
                            slot(r.z, lowest_slot.z, nb.z)},
                           LocalMapGeometry::local_in_brick(r));
  };

  const float tau = params.truncation_m;

  const int32_t free_from =
      ray.clock.ticks(free_space_from(ray.t_start, range, tau, map.voxel_size_m));
  // Jumps from the current voxel to the first one after its brick (brick_exit). Returns the
  // steps taken (-1: none possible).
  const auto leave_brick = [&]() -> int32_t {
    const int32_t place[3] = {offset[0] & (kBrickSize - 1), offset[1] & (kBrickSize - 1),
                              offset[2] & (kBrickSize - 1)};
    BrickExit exit;
    if (!brick_exit(step, place, t_next, t_delta, exit)) return -1;
    for (int axis = 0; axis < 3; ++axis) {
      const int32_t moved = step[axis] * exit.crossed[axis];
      t_next[axis] = exit.t_next[axis];
      offset[axis] += moved;
    }
    t = exit.t;
    return exit.crossed[0] + exit.crossed[1] + exit.crossed[2];
  };

  // Whether the voxel lies in the map, its storage index, and the brick it lies in. A brick's
  // settled flag is loaded as the walk enters it and looked at in the next turn, so that the
  // load's latency passes while the step finishes.
  bool inside = contains();
  WalkIndex index = storage_index();
  WalkIndex brick = index / kBrickVoxels;
  const auto settled_flag = [&] {
    return settled_bricks != nullptr && inside ? settled_bricks[brick] : uint8_t{0};
  };
#ifdef __CUDA_ARCH__
  constexpr bool kFreeWalks = false;
#else
  // Where the visitor takes the free space at the end of a walk whole (FreeWalk).
  constexpr bool kFreeWalks = TakesFreeWalks<std::remove_reference_t<Visit>>::value;
#endif
  // The walk's first brick and each one it enters, where it may jump or hand free space over.
  bool new_brick = settled_bricks != nullptr || kFreeWalks;
  uint8_t brick_settled = settled_flag();
  const auto enter_brick = [&] {
    brick = index / kBrickVoxels;
    new_brick = settled_bricks != nullptr || kFreeWalks;
    brick_settled = settled_flag();
  };
  // The GPU computes the storage index from the offset after every step: a dozen instructions
  // that a warp's lanes run together, where code for the step out of a brick, taken by a few
  // lanes at a time, made the warp wait (a fifth of the walk's instructions). The CPU moves the
  // index along with the step, and computes it only where a step leaves the brick (one step in
  // eight; computing it at every step made the CPU's walk 10 % slower); the walk can leave or
  // enter the map only there too (the map is whole bricks).
  const auto advance = [&](bool taken, auto axis_constant) {
    constexpr int axis = decltype(axis_constant)::value;
    const int32_t s = taken ? step[axis] : 0;
    if (taken) t = t_next[axis];
    t_next[axis] = taken ? t_next[axis] + t_delta[axis] : t_next[axis];
    offset[axis] += s;
#ifndef __CUDA_ARCH__
    constexpr WalkIndex local_stride = axis == 0   ? 1
                                       : axis == 1 ? kBrickSize
                                                   : kBrickVoxels / kBrickSize;
    if ((((offset[axis] - s) ^ offset[axis]) >> kBrickShift) != 0) {  // into the next brick
      inside = contains();
      index = storage_index();
      enter_brick();
    } else {
      index += static_cast<WalkIndex>(s) * local_stride;
    }
#endif
  };
  for (int32_t i = first_turn; i < end_turn; ++i) {
    // From free_from on, every voxel is free space (free_space_from): march_ray's distance
    // there is always >= tau, so it is not computed.
    const bool in_free_space = t >= free_from;
    bool jump = false;
    if (new_brick) {
      new_brick = false;
      // A brick inside the map lies wholly inside it (the map is whole bricks).
      jump = inside && in_free_space && brick_settled != 0;
      if constexpr (kFreeWalks) {
        if (inside && in_free_space) {
          visit.free_walk(FreeWalk{{offset[0], offset[1], offset[2]},
                                   {t_next[0], t_next[1], t_next[2]},
                                   {t_delta[0], t_delta[1], t_delta[2]},
                                   {step[0], step[1], step[2]},
                                   end_turn - i});
          return;
        }
      }
    }
    // One if-else per turn, no early turn back to the loop's head: on the GPU, the lanes of a
    // warp then meet again at the end of every turn.
    if (jump) {
      const int32_t taken = leave_brick();
      if (taken < 0 || i + taken >= end_turn) break;  // the part ends in this brick
      i += taken - 1;                                 // the loop adds the last one
      inside = contains();
      index = storage_index();
      enter_brick();
    } else {
      if (inside) {
        if (in_free_space) {
          visit(index, kValueScale, false);
        } else {
          const Index3 g{offset[0] + map.origin.x, offset[1] + map.origin.y,
                         offset[2] + map.origin.z};
          const Vec3 centre = map.centre_of(g);
          const float along = dot(centre - origin, dir);
          const float distance = range - along;
          if (distance >= tau) {
            visit(index, kValueScale, false);
          } else if (distance >= -tau) {
            const int32_t value = distance_to_fixed(distance, tau);
            visit(index, value, false);
            if (ray.interpolate) {
              for_each_interpolated_voxel(
                  map, centre, ray.across, params.interpolation_slope * along, [&](Index3 v) {
                    visit(static_cast<WalkIndex>(linear_of_contained(v)), value, true);
                  });
            }
          }
        }
      }
      // Step into the neighbour across the nearest voxel face (march_ray's rule). Which axis
      // comes next follows no pattern: the CPU branches (the prediction lets the next steps
      // start early; a miss costs less than computing all three), the GPU computes all three
      // axes with selects (branches would split a warp three ways). Every array is indexed
      // by a constant, so the traversal state stays in registers.
      const bool y_first = t_next[1] < t_next[0];
      const bool along_z = t_next[2] < (y_first ? t_next[1] : t_next[0]);
      constexpr std::integral_constant<int, 0> x;
      constexpr std::integral_constant<int, 1> y;
      constexpr std::integral_constant<int, 2> z;
#ifdef __CUDA_ARCH__
      advance(!along_z && !y_first, x);
      advance(!along_z && y_first, y);
      advance(along_z, z);
#else
      if (along_z) {
        advance(true, z);
      } else if (y_first) {
        advance(true, y);
      } else {
        advance(true, x);
      }
#endif
#ifdef __CUDA_ARCH__
      inside = contains();  // the GPU's, after every step (advance)
      index = storage_index();
      if (index / kBrickVoxels != brick) enter_brick();
#endif
    }
  }
}

}  // namespace featsense::tsdf::detail
