// The table that merges free-space words before they are handed on (free_word_cache.hpp):
// whatever is added comes out, each word's bits OR-ed, however words collide in their slots.

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <random>

#include "cpu_fast/free_word_cache.hpp"

namespace featsense::tsdf::detail {
namespace {

TEST(FreeWordCache, HandsOnEveryWordWithAllItsBits) {
  std::mt19937_64 random(7);
  // Words from a small set (they stay and merge) and from a large one (they collide).
  std::uniform_int_distribution<size_t> near(0, 500);
  std::uniform_int_distribution<size_t> far(0, size_t{1} << 34);
  std::map<size_t, uint64_t> added;
  std::map<size_t, uint64_t> handed;
  size_t hand_ons = 0;
  const auto hand_on = [&](size_t word, uint64_t bits) {
    handed[word] |= bits;
    ++hand_ons;
  };
  FreeWordCache cache;
  constexpr int kAdds = 200000;
  for (int k = 0; k < kAdds; ++k) {
    const size_t word = k % 3 == 0 ? far(random) : near(random);
    const uint64_t bits = random() & random();
    added[word] |= bits;
    cache.add(word, bits, hand_on);
  }
  EXPECT_LT(hand_ons, kAdds / 2u);  // the near words merged
  cache.flush(hand_on);
  EXPECT_EQ(handed, added);

  // Empty after a flush: nothing more comes out.
  hand_ons = 0;
  cache.flush(hand_on);
  EXPECT_EQ(hand_ons, 0u);
}

TEST(FreeWordCache, AWordAddedAgainStaysInItsSlot) {
  FreeWordCache cache;
  size_t hand_ons = 0;
  uint64_t bits_out = 0;
  const auto hand_on = [&](size_t, uint64_t bits) {
    ++hand_ons;
    bits_out |= bits;
  };
  EXPECT_TRUE(cache.add(42, 1, hand_on));
  EXPECT_FALSE(cache.add(42, 2, hand_on));
  EXPECT_FALSE(cache.add(42, 8, hand_on));
  EXPECT_EQ(hand_ons, 0u);
  cache.flush(hand_on);
  EXPECT_EQ(hand_ons, 1u);
  EXPECT_EQ(bits_out, 11u);
}

}  // namespace
}  // namespace featsense::tsdf::detail
