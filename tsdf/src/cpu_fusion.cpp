// The CPU integrator's fusion (cpu_integrator.hpp): each sector's task fuses the bricks its
// walks listed, brick by brick, asking for their data ahead, and renews their settled bits.

#include <atomic>

#include "cpu_fast/free_space_fusion.hpp"
#include "cpu_integrator.hpp"

namespace featsense::tsdf::detail {

/// Fuses the candidates of the listed bricks into the map, resets them, and returns how
/// many voxels were updated. Brick by brick, so memory is read in whole cache lines.
size_t CpuIntegrator::fuse(const std::vector<uint32_t>& bricks) {
  const uint32_t max_weight = settings_.max_weight_fixed();
  const int32_t falloff = settings_.falloff_start_fixed();
  size_t updated = 0;
  for (size_t k = 0; k < bricks.size(); ++k) {
    if (k + 4 < bricks.size()) prefetch_bits(bricks[k + 4]);
    if (k + 2 < bricks.size()) prefetch_voxels(bricks[k + 2]);
    if (k + 1 < bricks.size()) prefetch_candidates(bricks[k + 1]);
    updated += fuse_brick(bricks[k], falloff, max_weight);
    brick_listed_[bricks[k]] = 0;
  }
  return updated;
}

// The listed bricks lie all over the map, so a brick's data is seldom in a cache: the
// fusion asks for it ahead, the bit words four bricks ahead, every cache line of the voxels
// two bricks ahead and, from the bits, those of the candidates one brick ahead. Asking for
// the voxels' lines from the bits too made each prefetch wait for the bits first: the fusion
// then still waited for memory at most bricks (real OS1-128 frames on 2 cores: 17 -> 11 ms).
inline void CpuIntegrator::prefetch_bits(size_t brick) const {
  __builtin_prefetch(&occupancy_[brick * kWordsPerBrick]);
  __builtin_prefetch(&free_space_[brick * kWordsPerBrick]);
  __builtin_prefetch(&settled_[brick * kWordsPerBrick]);
}

inline void CpuIntegrator::prefetch_voxels(size_t brick) const {
  for (size_t line = 0; line < kBrickVoxels / kVoxelsPerLine; ++line) {
    __builtin_prefetch(&map_[brick * kBrickVoxels + line * kVoxelsPerLine], 1);
  }
}

inline void CpuIntegrator::prefetch_candidates(size_t brick) const {
  for (size_t word = brick * kWordsPerBrick; word < (brick + 1) * kWordsPerBrick; ++word) {
    const uint64_t with_key = occupancy_[word];
    for (size_t line = 0; line < 64 / kVoxelsPerLine; ++line) {
      const uint64_t mask = ((uint64_t{1} << kVoxelsPerLine) - 1) << (line * kVoxelsPerLine);
      if ((with_key & mask) != 0) {
        __builtin_prefetch(&candidates_[word * 64 + line * kVoxelsPerLine], 1);
      }
    }
  }
}

/// Fuses the candidates of one brick, and +tau where its free-space bits are set (the
/// smaller key wins), visiting only the voxels its occupancy bits name (testing every voxel
/// for a candidate mispredicts a branch on most partly touched bricks), then the voxels of
/// free space alone eight at a time (free_space_fusion.hpp); resets the bits and returns how
/// many voxels there were.
inline size_t CpuIntegrator::fuse_brick(size_t brick, int32_t falloff, uint32_t max_weight) {
  size_t updated = 0;
  for (size_t word = brick * kWordsPerBrick; word < (brick + 1) * kWordsPerBrick; ++word) {
    const uint64_t with_key = occupancy_[word];
    const uint64_t passed_free = free_space_[word];
    occupancy_[word] = 0;
    free_space_[word] = 0;
    uint64_t settled = settled_[word];
    for (uint64_t bits = with_key; bits != 0; bits &= bits - 1) {
      const uint64_t bit = bits & (~bits + 1);
      const size_t index = word * 64 + static_cast<size_t>(__builtin_ctzll(bits));
      uint32_t key = candidates_[index].load(std::memory_order_relaxed);
      candidates_[index].store(kEmptyCandidate, std::memory_order_relaxed);
      if ((passed_free & bit) != 0 && kFreeSpaceKey < key) key = kFreeSpaceKey;
      const int32_t value = candidate_value(key);
      const uint32_t fused = pack(
          tsdf::fuse(unpack(map_[index]), value, candidate_weight(value, falloff), max_weight));
      map_[index] = fused;
      settled = fused == settled_voxel_ ? settled | bit : settled & ~bit;
    }
    // Free space alone: +tau with its weight, the same candidate everywhere.
    settled =
        fuse_free_space_word(&map_[word * 64], passed_free & ~with_key, settled,
                             candidate_weight(kValueScale, falloff), max_weight, settled_voxel_);
    settled_[word] = settled;
    updated += static_cast<size_t>(__builtin_popcountll(with_key | passed_free));
  }
  note_settled_brick(brick);
  return updated;
}

}  // namespace featsense::tsdf::detail
