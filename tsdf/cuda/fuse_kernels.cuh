#pragma once
// The fusion: the bricks the walks marked, listed in two lists (with candidates; only passed
// in free space), and a kernel for each list that fuses their voxels, resets the scan's
// candidates and bits, and renews the settled bits. Included by cuda_integrator.cu only.

#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>

#include "featsense/tsdf/local_map_geometry.hpp"
#include "featsense/tsdf/voxel.hpp"
#include "kernel_common.cuh"

namespace featsense::tsdf::cuda {

/// The marked bricks, listed for the fusion: those with a candidate, and those only passed in
/// free space (most of them), which the fusion treats apart.
__global__ void list_touched_bricks_kernel(const uint32_t* brick_flags, const uint32_t* band_bricks,
                                           uint32_t brick_count, uint32_t* band_list,
                                           uint32_t* band_count, uint32_t* free_list,
                                           uint32_t* free_count) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  const bool touched = i < brick_count && brick_flags[i] != 0u;
  const bool band = touched && band_bricks[i] != 0u;
  append_warp_items(band, i, band_list, band_count);
  append_warp_items(touched && !band, i, free_list, free_count);
}

/// A brick's voxels as a warp fuses them: 16 rounds of 32 consecutive voxels, lane l taking
/// voxel 32 r + l of round r.
constexpr int kFuseRounds = kBrickVoxels / 32;

/// One warp per brick that was only passed in free space (no candidate): fuses +tau,
/// measured, into the voxels whose bit is set (none of them settled: the walks leave settled
/// voxels out), resets the bits and the brick's flag, and renews its settled bits and flag.
/// Rounds without a bit are skipped (the whole warp sees the same word) and keep their settled
/// bits. A kernel of its own: without keys it needs half the registers of the other bricks'
/// fusion, and the code of neither slows the other.
__global__ void __launch_bounds__(kThreads, 4)
    fuse_free_bricks_kernel(const uint32_t* __restrict__ free_bricks,
                            const uint32_t* __restrict__ free_count,
                            uint32_t* __restrict__ brick_flags, uint32_t* __restrict__ map,
                            uint32_t* __restrict__ settled, uint32_t* __restrict__ free_space,
                            uint8_t* __restrict__ settled_bricks, int32_t falloff,
                            uint32_t max_weight, uint32_t* __restrict__ voxels_updated) {
  const uint32_t count = *free_count;
  const uint32_t settled_voxel = settled_free_voxel(max_weight);
  const uint32_t free_weight = candidate_weight(kValueScale, falloff);
  const uint32_t lane = threadIdx.x % 32u;
  const uint32_t warps = gridDim.x * blockDim.x / 32u;
  uint32_t updated = 0;  // lane 0's count over its bricks
  // A warp's bricks pass through a pipeline, so that its three waits for memory overlap: while
  // one brick's voxels are fused, the next one's bit words and the index of the one after are
  // on their way (otherwise each brick waits for its index, then its words, then its voxels).
  const bool word_lane = lane < static_cast<uint32_t>(kFuseRounds);
  const auto brick_at = [&](uint32_t k) { return k < count ? free_bricks[k] : 0u; };
  const auto word_of = [&](const uint32_t* bits, uint32_t k, uint32_t brick) {
    return k < count && word_lane ? bits[static_cast<size_t>(brick) * (kBrickVoxels / 32) + lane]
                                  : 0u;
  };
  uint32_t k = (blockIdx.x * blockDim.x + threadIdx.x) / 32u;
  uint32_t brick = brick_at(k);
  uint32_t settled_word = word_of(settled, k, brick);
  uint32_t free_word = word_of(free_space, k, brick);
  uint32_t next_brick = brick_at(k + warps);
  for (; k < count; k += warps) {
    const uint32_t next_settled = word_of(settled, k + warps, next_brick);
    const uint32_t next_free = word_of(free_space, k + warps, next_brick);
    const uint32_t brick_after = brick_at(k + 2 * warps);
    const size_t first = static_cast<size_t>(brick) * kBrickVoxels;
    if (free_word != 0u) free_space[first / 32 + lane] = 0u;
    uint32_t voxels[kFuseRounds];
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      const bool passed = ((__shfl_sync(0xffffffffu, free_word, r) >> lane) & 1u) != 0u;
      voxels[r] = passed ? map[first + r * 32 + lane] : 0u;
    }
    bool all_settled = true;
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      const uint32_t passed_word = __shfl_sync(0xffffffffu, free_word, r);
      uint32_t word = __shfl_sync(0xffffffffu, settled_word, r);
      if (passed_word != 0u) {
        const size_t index = first + r * 32 + lane;
        bool is_settled = ((word >> lane) & 1u) != 0u;
        if (((passed_word >> lane) & 1u) != 0u) {
          const uint32_t fused =
              pack(fuse(unpack(voxels[r]), kValueScale, free_weight, max_weight));
          map[index] = fused;
          is_settled = fused == settled_voxel;
        }
        word = write_warp_bits(settled, index, is_settled);
        updated += static_cast<uint32_t>(__popc(passed_word));
      }
      all_settled = all_settled && word == 0xffffffffu;
    }
    if (lane == 0u) {
      brick_flags[brick] = 0u;
      settled_bricks[brick] = all_settled ? 1u : 0u;
    }
    brick = next_brick;
    settled_word = next_settled;
    free_word = next_free;
    next_brick = brick_after;
  }
  if (lane == 0u && updated != 0u) atomicAdd(voxels_updated, updated);
}

/// One warp per brick with a candidate: fuses the candidates, and +tau where a free-space bit
/// is set, into the map, resets them and the brick's flags for the next scan, and renews the
/// brick's settled bits and flag. Each lane first loads all its 16 keys, then the map voxels of
/// those that got one, so that a warp has up to 32 loads in flight: with one voxel a thread and
/// a barrier per brick, the fusion waited for memory brick by brick (a quarter of an outdoor
/// scan's time).
// At most 64 registers (four blocks a multiprocessor instead of three): more warps waiting
// for memory at once outweigh the few values it keeps in local memory (outdoor fusion 210 ->
// 200 µs on an H100).
__global__ void __launch_bounds__(kThreads, 4)
    fuse_bricks_kernel(const uint32_t* __restrict__ touched_bricks,
                       const uint32_t* __restrict__ touched_count,
                       uint32_t* __restrict__ brick_flags, uint32_t* __restrict__ band_bricks,
                       uint32_t* __restrict__ candidates, uint32_t* __restrict__ map,
                       uint32_t* __restrict__ settled, uint32_t* __restrict__ free_space,
                       uint8_t* __restrict__ settled_bricks, int32_t falloff, uint32_t max_weight,
                       uint32_t* __restrict__ voxels_updated) {
  const uint32_t count = *touched_count;
  const uint32_t settled_voxel = settled_free_voxel(max_weight);
  const uint32_t lane = threadIdx.x % 32u;
  const uint32_t warps = gridDim.x * blockDim.x / 32u;
  uint32_t updated_here = 0;  // lane 0's count of updated voxels over its bricks
  for (uint32_t k = (blockIdx.x * blockDim.x + threadIdx.x) / 32u; k < count; k += warps) {
    const uint32_t brick = touched_bricks[k];
    const size_t first = static_cast<size_t>(brick) * kBrickVoxels;
    // The brick's 16 words of settled and of free-space bits, word r in lane r; the
    // free-space bits are reset for the next scan.
    const bool word_lane = lane < static_cast<uint32_t>(kFuseRounds);
    const uint32_t settled_word = word_lane ? settled[first / 32 + lane] : 0u;
    const uint32_t free_word = word_lane ? free_space[first / 32 + lane] : 0u;
    if (free_word != 0u) free_space[first / 32 + lane] = 0u;
    uint32_t keys[kFuseRounds];
    uint32_t voxels[kFuseRounds];
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      keys[r] = candidates[first + r * 32 + lane];
    }
    uint32_t stored = 0;  // bit r: the candidate slot of round r holds a key to reset
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      if (keys[r] != kEmptyCandidate) stored |= 1u << r;
      const bool passed_free = ((__shfl_sync(0xffffffffu, free_word, r) >> lane) & 1u) != 0u;
      if (passed_free && kFreeSpaceKey < keys[r]) keys[r] = kFreeSpaceKey;
      voxels[r] = keys[r] != kEmptyCandidate ? map[first + r * 32 + lane] : 0u;
    }
    bool all_settled = true;
#pragma unroll
    for (int r = 0; r < kFuseRounds; ++r) {
      const size_t index = first + r * 32 + lane;
      const bool updated = keys[r] != kEmptyCandidate;
      bool is_settled = ((__shfl_sync(0xffffffffu, settled_word, r) >> lane) & 1u) != 0u;
      if (updated) {
        if (((stored >> r) & 1u) != 0u) candidates[index] = kEmptyCandidate;
        const int32_t value = candidate_value(keys[r]);
        const uint32_t fused =
            pack(fuse(unpack(voxels[r]), value, candidate_weight(value, falloff), max_weight));
        map[index] = fused;
        is_settled = fused == settled_voxel;
      }
      const uint32_t word = write_warp_bits(settled, index, is_settled);
      const uint32_t updated_lanes = __ballot_sync(0xffffffffu, updated);
      if (lane == 0u) updated_here += static_cast<uint32_t>(__popc(updated_lanes));
      all_settled = all_settled && word == 0xffffffffu;
    }
    if (lane == 0u) {
      brick_flags[brick] = 0u;
      band_bricks[brick] = 0u;
      settled_bricks[brick] = all_settled ? 1u : 0u;
    }
  }
  if (lane == 0u && updated_here != 0u) atomicAdd(voxels_updated, updated_here);
}

}  // namespace featsense::tsdf::cuda
