#pragma once
// What several of the CUDA integrator's kernels share: the block size, and the warp-wide
// writes of bits and list items. Included by cuda_integrator.cu only (one translation unit
// holds all the kernels).

#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>

namespace featsense::tsdf::cuda {

constexpr int kThreads = 256;

unsigned int blocks_for(size_t n) {
  return static_cast<unsigned int>((n + kThreads - 1) / kThreads);
}

/// Sets each lane's voxel bit in a bit set of 32-bit words (the settled bits), where a warp's
/// 32 consecutive voxels are a word, and returns the word. The whole warp calls it, on 32
/// consecutive voxels starting at a multiple of 32.
__device__ uint32_t write_warp_bits(uint32_t* bits, size_t index, bool bit) {
  const uint32_t word = __ballot_sync(0xffffffffu, bit);
  if (threadIdx.x % 32u == 0u) bits[index / 32] = word;
  return word;
}

/// Appends the calling lanes' items to a list, one atomic per warp (in no particular order).
__device__ void append_warp_items(bool take, uint32_t item, uint32_t* list, uint32_t* count) {
  const unsigned int lanes = __ballot_sync(0xffffffffu, take);
  if (lanes == 0u) return;
  const int lane = static_cast<int>(threadIdx.x % 32u);
  const int leader = __ffs(static_cast<int>(lanes)) - 1;
  uint32_t first = 0;
  if (lane == leader) first = atomicAdd(count, static_cast<uint32_t>(__popc(lanes)));
  first = __shfl_sync(0xffffffffu, first, leader);
  if (take) list[first + __popc(lanes & ((1u << lane) - 1u))] = item;
}

}  // namespace featsense::tsdf::cuda
