#pragma once
// The CPU's fusion of free space alone: most voxels a scan updates were only passed by rays
// (+tau), and most of those hold +tau already or nothing, where the weighted average is +tau
// and only the weight grows: no candidate to read, no division. Any other voxel gets
// tsdf::fuse itself, so the result is the same voxel for voxel.
//
// Such words are dense (on the real OS1-128 frames, 35 of a word's 64 voxels on average), so
// where the processor has AVX2 (chosen at run time; the build targets baseline x86-64), eight
// voxels are fused at a time.

#include <cstdint>

#include "cpu_features.hpp"
#include "featsense/tsdf/voxel.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define FEATSENSE_FREE_SPACE_FUSION_AVX2 1
#else
#define FEATSENSE_FREE_SPACE_FUSION_AVX2 0
#endif

namespace featsense::tsdf::detail {

/// fuse_free_space_word for one voxel: returns `settled` with its bit set where the voxel now
/// holds `settled_voxel`, cleared where not.
inline uint64_t fuse_free_space_voxel(uint32_t& voxel, int lane, uint64_t settled, uint32_t weight,
                                      uint32_t max_weight, uint32_t settled_voxel) {
  constexpr auto kFree = static_cast<uint32_t>(kValueScale);
  const uint32_t held_weight = voxel >> 16;
  if ((voxel & 0xFFFFu) == kFree || held_weight == 0u) {
    const uint32_t grown = held_weight + weight;
    voxel = ((grown < max_weight ? grown : max_weight) << 16) | kFree;
  } else {
    voxel = pack(fuse(unpack(voxel), kValueScale, weight, max_weight));
  }
  const uint64_t bit = uint64_t{1} << lane;
  return voxel == settled_voxel ? settled | bit : settled & ~bit;
}

/// The plain version of fuse_free_space_word: a voxel at a time.
inline uint64_t fuse_free_space_word_plain(uint32_t* voxels, uint64_t bits, uint64_t settled,
                                           uint32_t weight, uint32_t max_weight,
                                           uint32_t settled_voxel) {
  for (; bits != 0; bits &= bits - 1) {
    const int lane = __builtin_ctzll(bits);
    settled = fuse_free_space_voxel(voxels[lane], lane, settled, weight, max_weight, settled_voxel);
  }
  return settled;
}

#if FEATSENSE_FREE_SPACE_FUSION_AVX2
/// fuse_free_space_word eight voxels at a time, for processors with AVX2. Voxels of a group of
/// eight that `bits` leaves out are written back as they were (a brick is fused by one thread).
__attribute__((target("avx2"))) inline uint64_t fuse_free_space_word_avx2(
    uint32_t* voxels, uint64_t bits, uint64_t settled, uint32_t weight, uint32_t max_weight,
    uint32_t settled_voxel) {
  const __m256i lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  const __m256i free_value = _mm256_set1_epi32(kValueScale);
  const __m256i low_half = _mm256_set1_epi32(0xFFFF);
  const __m256i added = _mm256_set1_epi32(static_cast<int32_t>(weight));
  const __m256i cap = _mm256_set1_epi32(static_cast<int32_t>(max_weight));
  const __m256i settled_value = _mm256_set1_epi32(static_cast<int32_t>(settled_voxel));
  for (int group = 0; group < 8; ++group) {
    const auto chosen = static_cast<uint32_t>(bits >> (group * 8)) & 0xFFu;
    if (chosen == 0) continue;
    uint32_t* const at = voxels + group * 8;
    const __m256i held = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(at));
    const __m256i in = _mm256_cmpeq_epi32(
        _mm256_and_si256(_mm256_set1_epi32(static_cast<int32_t>(chosen)), lane_bit), lane_bit);
    const __m256i held_weight = _mm256_srli_epi32(held, 16);
    const __m256i plain =
        _mm256_or_si256(_mm256_cmpeq_epi32(_mm256_and_si256(held, low_half), free_value),
                        _mm256_cmpeq_epi32(held_weight, _mm256_setzero_si256()));
    const __m256i take = _mm256_and_si256(in, plain);
    const __m256i grown = _mm256_min_epu32(_mm256_add_epi32(held_weight, added), cap);
    const __m256i fused = _mm256_or_si256(_mm256_slli_epi32(grown, 16), free_value);
    const __m256i out = _mm256_blendv_epi8(held, fused, take);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(at), out);
    // A bit per lane, from the lanes' sign bits.
    uint64_t group_settled = static_cast<uint32_t>(_mm256_movemask_ps(
        _mm256_castsi256_ps(_mm256_and_si256(take, _mm256_cmpeq_epi32(out, settled_value)))));
    const auto rest_lanes = static_cast<uint32_t>(
        _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_andnot_si256(plain, in))));
    for (uint32_t rest = rest_lanes; rest != 0; rest &= rest - 1) {
      const int lane = __builtin_ctz(rest);
      group_settled =
          fuse_free_space_voxel(at[lane], lane, group_settled, weight, max_weight, settled_voxel);
    }
    const int shift = group * 8;
    settled = (settled & ~(uint64_t{chosen} << shift)) | (group_settled << shift);
  }
  return settled;
}
#endif

/// Fuses +tau with `weight` (what a free-space candidate gives, candidate_weight) into the
/// voxels of one 64-voxel word that `bits` names; returns `settled` with their bits set where
/// they now hold `settled_voxel` and cleared where they do not.
inline uint64_t fuse_free_space_word(uint32_t* voxels, uint64_t bits, uint64_t settled,
                                     uint32_t weight, uint32_t max_weight, uint32_t settled_voxel) {
  if (weight == 0u) return settled;  // fuse leaves every voxel as it is
#if FEATSENSE_FREE_SPACE_FUSION_AVX2
  if (cpu_has_avx2()) {
    return fuse_free_space_word_avx2(voxels, bits, settled, weight, max_weight, settled_voxel);
  }
#endif
  return fuse_free_space_word_plain(voxels, bits, settled, weight, max_weight, settled_voxel);
}

}  // namespace featsense::tsdf::detail
