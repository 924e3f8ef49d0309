#pragma once
// Free-space words gathered before they are handed on. Rays near the sensor pass the same
// words again and again: on an OS1-128-like scan in a box room, the lanes write out 7.6 M words
// of which only 0.22 M differ (bench_ray_walk), and handing each on reads two bit words of
// the map that are seldom cached. A small table, one word a slot, merges the bits of a word
// while it stays, and hands it on when another word takes its slot (0.68 M times there).

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace featsense::tsdf::detail {

class FreeWordCache {
 public:
  FreeWordCache() : word_(kSlots, kEmpty), bits_(kSlots, 0) {}

  /// Adds `bits` of `word`; hand_on(word, bits) for the word whose slot it takes, if any.
  /// True where the word took a slot anew (to be handed on later, by a later add or flush).
  template <typename HandOn>
  bool add(size_t word, uint64_t bits, HandOn&& hand_on) {
    const size_t slot = slot_of(word);
    if (word_[slot] == word) {
      bits_[slot] |= bits;
      return false;
    }
    if (word_[slot] != kEmpty) hand_on(word_[slot], bits_[slot]);
    word_[slot] = word;
    bits_[slot] = bits;
    return true;
  }

  /// Hands every word held on, and empties the table.
  template <typename HandOn>
  void flush(HandOn&& hand_on) {
    for (size_t slot = 0; slot < kSlots; ++slot) {
      if (word_[slot] == kEmpty) continue;
      hand_on(word_[slot], bits_[slot]);
      word_[slot] = kEmpty;
    }
  }

 private:
  static constexpr int kSlotBits = 12;
  static constexpr size_t kSlots = size_t{1} << kSlotBits;
  static constexpr size_t kEmpty = std::numeric_limits<size_t>::max();

  /// Fibonacci hashing: neighbouring words (a brick's eight, the bricks of a row) fall into
  /// slots far apart.
  static size_t slot_of(size_t word) {
    return static_cast<size_t>((word * 0x9E3779B97F4A7C15ull) >> (64 - kSlotBits));
  }

  std::vector<size_t> word_;
  std::vector<uint64_t> bits_;
};

}  // namespace featsense::tsdf::detail
