#pragma once
// The CPU's fusion of free space alone: most voxels a scan updates were only passed by rays
// (+tau), and most of those hold +tau already or nothing, where the weighted average is +tau
// and only the weight grows: no candidate to read, no division. Any other voxel gets
// tsdf::fuse itself, so the result is the same voxel for voxel.

#include <cstdint>

#include "featsense/tsdf/voxel.hpp"

namespace featsense::tsdf::detail {

/// Fuses +tau with `weight` (what a free-space candidate gives, candidate_weight) into the
/// voxels of one 64-voxel word that `bits` names; returns `settled` with their bits set where
/// they now hold `settled_voxel` and cleared where they do not.
inline uint64_t fuse_free_space_word(uint32_t* voxels, uint64_t bits, uint64_t settled,
                                     uint32_t weight, uint32_t max_weight, uint32_t settled_voxel) {
  if (weight == 0u) return settled;  // fuse leaves every voxel as it is
  constexpr auto kFree = static_cast<uint32_t>(kValueScale);
  for (; bits != 0; bits &= bits - 1) {
    const int lane = __builtin_ctzll(bits);
    const uint32_t held = voxels[lane];
    const uint32_t held_weight = held >> 16;
    uint32_t fused;
    if ((held & 0xFFFFu) == kFree || held_weight == 0u) {
      const uint32_t grown = held_weight + weight;
      fused = ((grown < max_weight ? grown : max_weight) << 16) | kFree;
    } else {
      fused = pack(fuse(unpack(held), kValueScale, weight, max_weight));
    }
    voxels[lane] = fused;
    const uint64_t bit = uint64_t{1} << lane;
    settled = fused == settled_voxel ? settled | bit : settled & ~bit;
  }
  return settled;
}

}  // namespace featsense::tsdf::detail
