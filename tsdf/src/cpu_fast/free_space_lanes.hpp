#pragma once
// The CPU's free-space walks eight at a time. A walk's step goes along whichever axis's
// crossing comes next, which follows no pattern: the scalar loop (free_space_walk.hpp) branches
// on it and mispredicts about every other voxel, which was most of its 14 cycles a voxel on the
// real OS1-128 frames. Here each of eight AVX2 lanes walks a ray of its own and every lane takes
// the same instructions at every step: which axis steps and whether the step leaves the brick
// are masks, and a word of 64 voxels is written out (compressed: the lanes that finished one
// only) where a lane leaves it. A lane whose walk ends takes the next walk.
//
// A walk is cut, before a lane takes it, where it leaves the map or crosses the ring buffer's
// seam (computed from its crossings), so that inside a part a step out of a brick always moves
// the storage brick by one stride: the lanes need no bounds and no wrap.
//
// Exact: each lane makes the scalar loop's steps in the same order (the same integer ticks,
// the lower axis first on ties). One difference, which leaves the map the same: bricks of
// settled free space are walked through, not jumped across. Their words are all settled, and
// every visitor of free words drops settled voxels (the jump only saves time).
//
// Where the processor has no AVX2 (chosen at run time; the build targets baseline x86-64),
// walk_free_space_job (free_space_walk.hpp) walks one set-aside walk with the scalar loop.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "free_space_walk.hpp"

namespace featsense::tsdf::detail {

/// Walks set-aside walks eight at a time (see above). Its state and output live across calls:
///   lanes.start(walks, count, map);
///   do { more = lanes.walk(); for k < lanes.words(): visit(lanes.word(k), lanes.bits(k)); }
///   while (more);
/// Word indices are 32-bit: a map of fewer than 2^37 voxels (far more than memory holds).
class FreeSpaceLanes {
 public:
  /// Whether this processor can run it (AVX2).
  static bool supported();

  FreeSpaceLanes();
  ~FreeSpaceLanes();
  FreeSpaceLanes(FreeSpaceLanes&&) noexcept;
  FreeSpaceLanes& operator=(FreeSpaceLanes&&) noexcept;

  /// Takes `walks` (kept by pointer until walk() returns false) into the lanes' queue.
  void start(const FreeWalk* walks, size_t count, const FreeSpaceMap& map);
  /// Walks until its output is nearly full (true: call again after taking it) or every walk
  /// is done (false). The output of the last call is replaced.
  bool walk();
  /// The words of free space of the last call: word index (storage index / 64) and bits.
  size_t words() const { return out_.count; }
  int32_t word(size_t k) const { return out_.word[k]; }
  uint64_t bits(size_t k) const { return (uint64_t{out_.high[k]} << 32) | out_.low[k]; }

  /// What a call writes out: the two halves of each word's bits apart, as the lanes hold them.
  struct Words {
    std::vector<int32_t> word;
    std::vector<uint32_t> low;
    std::vector<uint32_t> high;
    size_t count = 0;
  };

 private:
  struct State;
  Words out_;
  std::unique_ptr<State> state_;
};

}  // namespace featsense::tsdf::detail
