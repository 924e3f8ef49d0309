#pragma once
// The per-scan minimum: one thread per part of a ray walks it (ray_walk.hpp) and proposes its
// candidates, an atomicMin each on the ordered keys, and its free space as a bit per voxel.
// Included by cuda_integrator.cu only.

#include <cuda_runtime.h>

#include <cstdint>

#include "featsense/tsdf/local_map_geometry.hpp"
#include "featsense/tsdf/voxel.hpp"
#include "ray_walk.hpp"

namespace featsense::tsdf::cuda {

struct ProposeCandidate {
  LocalMapGeometry map;
  uint32_t* candidates;
  uint32_t* brick_flags;
  uint32_t* band_bricks;  ///< 1 per brick with a candidate this scan (not free space alone)
  const uint32_t* settled;
  uint32_t* free_space;  ///< a bit per voxel that a ray passed in free space this scan

  __device__ void operator()(uint32_t index, int32_t value, bool interpolated) const {
    // Both loads are issued before either is needed, so the walk waits for memory once per
    // voxel, not twice. Keys only decrease during a scan, so a stale read can only cause an
    // unneeded atomic.
    const uint32_t current = candidates[index];
    const uint32_t settled_word =
        passes_settled_by(value, interpolated) ? __ldg(&settled[index / 32]) : 0u;
    // Settled free space stays as it is (its bits are mostly in the L1 cache).
    if (((settled_word >> (index % 32)) & 1u) != 0u) return;
    const uint32_t key = make_candidate(value, interpolated);
    if (current <= key) return;
    // The old value is not needed, so the minimum is a reduction the thread does not wait for.
    atomicMin(&candidates[index], key);
    // Mark the brick for the fusion. The thread whose minimum lands first on an empty voxel
    // read it empty (nothing had landed before), so every touched brick gets marked.
    if (current == kEmptyCandidate) {
      brick_flags[index / kBrickVoxels] = 1u;
      band_bricks[index / kBrickVoxels] = 1u;
    }
  }
};

/// A thread's visitor: free space goes to a bit per voxel, the rest to ProposeCandidate.
/// Free space is most of a walk, and every free-space visit proposes the same key (+tau,
/// measured), so the scan's minimum only needs to know which voxels were passed: the fusion
/// takes min(candidate, +tau) where the bit is set, the same as if each visit had been an
/// atomicMin. The bits of the voxels in one 32-bit word (4 x 8 voxels of a brick) are
/// gathered while the walk stays in that word and then set with one atomicOr that the thread
/// does not wait for, so a free-space step waits for no memory at all (a candidate waits for
/// its key's load). Settled free space is left out: its bits, loaded on entering a word, are
/// cleared before the atomicOr.
struct WalkVisitor {
  const ProposeCandidate& propose;
  uint32_t word = 0xFFFFFFFFu;  // the word being gathered, none yet
  uint32_t bits = 0;
  uint32_t settled_word = 0;
  uint32_t marked_brick = 0xFFFFFFFFu;  // the brick this walk last marked for the fusion

  __device__ void operator()(uint32_t index, int32_t value, bool interpolated) {
    if (value != kValueScale || interpolated) {
      propose(index, value, interpolated);
      return;
    }
    const uint32_t w = index / 32;
    if (w != word) {
      flush();
      word = w;
      settled_word = __ldg(&propose.settled[w]);
    }
    bits |= 1u << (index % 32);
  }

  __device__ void flush() {
    const uint32_t fresh = bits & ~settled_word;
    bits = 0;
    if (fresh == 0u) return;
    atomicOr(&propose.free_space[word], fresh);
    // A brick's flag stays set until the fusion: once a walk has set it, it need not again
    // (most flushes stay in the brick of the last one).
    const uint32_t brick = word / (kBrickVoxels / 32);
    if (brick != marked_brick) {
      propose.brick_flags[brick] = 1u;
      marked_brick = brick;
    }
  }
};

/// Parts each ray's walk is cut into (ray_walk.hpp, WalkPart). Walks differ in length by 100x
/// and a block's take as long as its longest, so with one block a ray's whole walk, some
/// multiprocessors finished in 60 % of the time of the last (a scan's blocks fit on the GPU
/// at once, so none were left to give them). In parts, the blocks are shorter and a second
/// wave of them fills the multiprocessors that finish first.
constexpr int32_t kWalkParts = 6;
constexpr float kWalkPartLength = 4.0f;  ///< metres

/// Threads a block of the walk: blocks of 128 rather than 256 end sooner, so the second wave's
/// blocks find room on the multiprocessors that finish first earlier (a scan's walk 270 ->
/// 260 µs on an H100).
constexpr unsigned int kWalkThreads = 128;

// At most 64 registers, so that 32 warps share a multiprocessor. (A walk without the limit
// takes 78 registers.)
__global__ void __launch_bounds__(kWalkThreads, 8)
    min_tsdf_kernel(const Vec3* origins, bool origin_per_point, const Vec3* endpoints,
                    const uint8_t* interpolate, const uint8_t* carving_level, bool carve_free_space,
                    float dense_range_m, const uint32_t* kept, const uint32_t* kept_count,
                    detail::RayMarchParams params, ProposeCandidate propose,
                    const uint8_t* settled_bricks) {
  // Block b walks part b % kWalkParts of the rays of block b / kWalkParts: the parts of a
  // ray are walked at about the same time, by neighbouring blocks.
  const uint32_t k = blockIdx.x / static_cast<uint32_t>(kWalkParts) * blockDim.x + threadIdx.x;
  if (k >= *kept_count) return;
  const uint32_t i = kept[k];
  const Vec3 origin = origins[origin_per_point ? i : 0];
  // A ray is cut into one part per kWalkPartLength of its length, at most kWalkParts: the
  // shorter ones need not pay for setting up parts they hardly need.
  const float length = norm(endpoints[i] - origin);
  const float wanted = length / kWalkPartLength;
  const int32_t count =
      wanted < static_cast<float>(kWalkParts) ? 1 + static_cast<int32_t>(wanted) : kWalkParts;
  const detail::WalkPart part{static_cast<int32_t>(blockIdx.x % static_cast<uint32_t>(kWalkParts)),
                              count};
  if (part.index >= part.count) return;
  detail::RayMarchParams ray = params;
  if (interpolate != nullptr && interpolate[i] == 0) ray.interpolation_slope = 0.0f;
  ray.carve_from_m =
      detail::carving_start(carve_free_space, dense_range_m,
                            carving_level == nullptr ? kFullCarvingLevel : carving_level[i]);
  WalkVisitor visit{propose};
  detail::walk_ray(origin, endpoints[i], propose.map, ray, visit, settled_bricks, part);
  visit.flush();
}

}  // namespace featsense::tsdf::cuda
