// The CPU fusion's path for free space alone (free_space_fusion.hpp) against the general rule,
// tsdf::fuse, voxel by voxel: unobserved voxels, +tau at every weight up to the cap, other
// values (surfaces, behind them), settled free space; sparse and dense words; both the plain
// loop and, where the processor has it, the AVX2 one.

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "cpu_fast/free_space_fusion.hpp"

namespace featsense::tsdf {
namespace {

struct Case {
  std::vector<uint32_t> voxels;  // one 64-voxel word
  uint64_t bits;
  uint64_t settled;
};

/// What the general rule gives: the voxels fused, and the settled bits of those voxels.
Case reference(Case c, uint32_t weight, uint32_t max_weight, uint32_t settled_voxel) {
  for (int lane = 0; lane < 64; ++lane) {
    if (((c.bits >> lane) & 1u) == 0u) continue;
    c.voxels[static_cast<size_t>(lane)] =
        pack(fuse(unpack(c.voxels[static_cast<size_t>(lane)]), kValueScale, weight, max_weight));
    const uint64_t bit = uint64_t{1} << lane;
    c.settled =
        c.voxels[static_cast<size_t>(lane)] == settled_voxel ? c.settled | bit : c.settled & ~bit;
  }
  return c;
}

/// A word of voxels as a map holds them, and which of them a scan passed.
Case random_case(std::mt19937& random, uint32_t max_weight, uint32_t settled_voxel) {
  Case c{std::vector<uint32_t>(64), 0, 0};
  for (uint32_t& v : c.voxels) {
    Voxel voxel;
    switch (random() % 5) {
      case 0:  // unobserved
        break;
      case 1:
      case 2:  // free space, any weight up to the cap
        voxel.value = static_cast<int16_t>(kValueScale);
        voxel.weight = static_cast<uint16_t>(1 + random() % max_weight);
        break;
      case 3:  // settled free space
        v = settled_voxel;
        continue;
      default:  // near or behind a surface
        voxel.value = static_cast<int16_t>(static_cast<int32_t>(random() % 65535) - 32767);
        voxel.weight = static_cast<uint16_t>(1 + random() % max_weight);
    }
    v = pack(voxel);
  }
  const uint64_t a = (uint64_t{random()} << 32) | random();
  const uint64_t b = (uint64_t{random()} << 32) | random();
  switch (random() % 4) {
    case 0:
      c.bits = a & b;
      break;  // sparse
    case 1:
      c.bits = a;
      break;
    case 2:
      c.bits = a | b;
      break;  // dense
    default:
      c.bits = ~uint64_t{0};
  }
  for (int lane = 0; lane < 64; ++lane) {
    if (c.voxels[static_cast<size_t>(lane)] == settled_voxel) c.settled |= uint64_t{1} << lane;
  }
  return c;
}

TEST(FreeSpaceFusion, EveryPathGivesWhatTheGeneralRuleGives) {
  std::mt19937 random(5);
  size_t checked = 0;
  for (const uint32_t max_weight : {640u, 64u * 500u, 65535u}) {
    const uint32_t settled_voxel = settled_free_voxel(max_weight);
    for (const uint32_t weight : {64u, 1u, 0u}) {
      for (int k = 0; k < 300; ++k) {
        const Case c = random_case(random, max_weight, settled_voxel);
        const Case expected = reference(c, weight, max_weight, settled_voxel);
        if (weight != 0) {  // the plain loop; weight 0 is the dispatcher's (nothing changes)
          Case plain = c;
          plain.settled = detail::fuse_free_space_word_plain(plain.voxels.data(), c.bits, c.settled,
                                                             weight, max_weight, settled_voxel);
          EXPECT_EQ(plain.voxels, expected.voxels);
          EXPECT_EQ(plain.settled, expected.settled);
        }
        Case chosen = c;  // what the integrator calls: AVX2 where the processor has it
        chosen.settled = detail::fuse_free_space_word(chosen.voxels.data(), c.bits, c.settled,
                                                      weight, max_weight, settled_voxel);
        EXPECT_EQ(chosen.voxels, expected.voxels);
        EXPECT_EQ(chosen.settled, expected.settled);
#if FEATSENSE_FREE_SPACE_FUSION_AVX2
        if (__builtin_cpu_supports("avx2") && weight != 0) {
          Case wide = c;
          wide.settled = detail::fuse_free_space_word_avx2(wide.voxels.data(), c.bits, c.settled,
                                                           weight, max_weight, settled_voxel);
          EXPECT_EQ(wide.voxels, expected.voxels);
          EXPECT_EQ(wide.settled, expected.settled);
        }
#endif
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 2700u);
}

}  // namespace
}  // namespace featsense::tsdf
