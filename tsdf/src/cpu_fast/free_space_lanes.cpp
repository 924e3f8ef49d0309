// Free-space walks eight at a time with AVX2 (free_space_lanes.hpp says why and what).

#include "free_space_lanes.hpp"

#include <limits>

#include "cpu_features.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define FEATSENSE_FREE_SPACE_LANES_AVX2 1
#else
#define FEATSENSE_FREE_SPACE_LANES_AVX2 0
#endif

namespace featsense::tsdf::detail {

namespace {
constexpr int kLanes = 8;
/// Words written out per walk() call at most (a step writes up to kLanes).
constexpr size_t kWordCapacity = 4096;

/// The place of a voxel in its brick as the lanes keep it: x + 8, y + 8 and z + 8 in fields of
/// five bits. A step adds or subtracts one in a field; the field then lies in [7, 16], and the
/// step left the brick where it is 7 or 16, the only values whose bits 3 and 4 are not 0b01.
/// `field & 7 | 8` then wraps it into the next brick (16 -> 8, 7 -> 15). The walk's place so
/// needs no test of the axis it stepped along.
constexpr int32_t kFieldBits = 5;
constexpr int32_t kPlaceBias = 8 | 8 << kFieldBits | 8 << 2 * kFieldBits;
constexpr int32_t kPlaceLow = 7 | 7 << kFieldBits | 7 << 2 * kFieldBits;
constexpr int32_t kPlaceGuard = 24 | 24 << kFieldBits | 24 << 2 * kFieldBits;

/// Crossings of `axis` before tick `tick` (those with t < tick).
int64_t crossings_before(const FreeWalk& w, int axis, int64_t tick) {
  if (w.step[axis] == 0 || tick <= w.t_next[axis]) return 0;
  return (tick - 1 - w.t_next[axis]) / w.t_delta[axis] + 1;
}

/// Cuts `walk` where it leaves the map or crosses the ring buffer's seam (where a brick's
/// slot jumps from the last to the first), so that inside a part the storage brick moves by
/// one stride a brick: `walk` keeps the voxels before that crossing; the rest, after it, goes to
/// `rest` (true), or nowhere where the walk leaves the map or ends first (false). The crossing
/// is the first of the crossings per axis that would take the walk there, in the walk's order
/// (t, the lower axis first on ties); the voxels before it are the crossings before it plus one.
bool cut_at_seam(FreeWalk& walk, FreeWalk& rest, const FreeSpaceMap& map) {
  constexpr int64_t kNone = std::numeric_limits<int64_t>::max();
  int64_t event_tick = kNone;
  int event_axis = -1;
  int64_t event_crossings = 0;  // along event_axis, itself included
  bool leaves = false;
  for (int axis = 0; axis < 3; ++axis) {
    const int32_t s = walk.step[axis];
    if (s == 0) continue;
    const int32_t o = walk.offset[axis];
    const int32_t dim = map.bricks[axis] * kBrickSize;
    // The first voxel of slot 0, where the ring buffer's seam lies inside the map.
    const int32_t seam = (map.bricks[axis] - map.lowest_slot[axis]) * kBrickSize;
    const bool has_seam = map.lowest_slot[axis] != 0;
    int64_t n = s > 0 ? dim - o : o + 1;  // crossings to leave the map
    bool leaving = true;
    if (has_seam && (s > 0 ? o < seam : o >= seam)) {
      const int64_t to_seam = s > 0 ? seam - o : o - seam + 1;
      if (to_seam < n) {
        n = to_seam;
        leaving = false;
      }
    }
    if (n >= walk.turns) continue;  // more crossings than the walk has voxels
    const int64_t tick = walk.t_next[axis] + (n - 1) * int64_t{walk.t_delta[axis]};
    if (tick < event_tick) {  // axes in increasing order: a tie keeps the lower one
      event_tick = tick;
      event_axis = axis;
      event_crossings = n;
      leaves = leaving;
    }
  }
  if (event_axis < 0) return false;
  int64_t crossed[3];
  int64_t before = 0;  // crossings before the event's
  for (int axis = 0; axis < 3; ++axis) {
    crossed[axis] = axis == event_axis
                        ? event_crossings - 1
                        : crossings_before(walk, axis, event_tick + (axis < event_axis ? 1 : 0));
    before += crossed[axis];
  }
  if (before + 1 >= walk.turns) return false;  // the walk ends first
  const int32_t total = walk.turns;
  walk.turns = static_cast<int32_t>(before + 1);
  if (leaves) return false;
  rest = walk;
  crossed[event_axis] += 1;  // the crossing of the seam itself
  for (int axis = 0; axis < 3; ++axis) {
    if (walk.step[axis] == 0) continue;
    rest.offset[axis] += walk.step[axis] * static_cast<int32_t>(crossed[axis]);
    rest.t_next[axis] += static_cast<int32_t>(crossed[axis]) * walk.t_delta[axis];
  }
  rest.turns = total - walk.turns;
  return true;
}
}  // namespace

/// The lanes' state, a row of kLanes per quantity (loaded as vectors), and the output.
struct FreeSpaceLanes::State {
  alignas(32) int32_t next[3][kLanes];     ///< the next crossing per axis (ticks)
  alignas(32) int32_t delta[3][kLanes];    ///< ticks between crossings
  alignas(32) int32_t place[kLanes];       ///< the voxel in its brick (kPlaceBias)
  alignas(32) int32_t left[kLanes] = {};   ///< voxels left to visit; <= 0: no walk
  alignas(32) int32_t low[kLanes];         ///< the word's bits 0-31 gathered so far
  alignas(32) int32_t high[kLanes];        ///< bits 32-63
  alignas(32) int32_t brick[kLanes];       ///< storage brick
  alignas(32) int32_t move[3][kLanes];     ///< what a step along the axis adds to the place
  alignas(32) int32_t forward[3][kLanes];  ///< what a step out of the brick adds to brick

  FreeWalk rest[kLanes];  ///< what a lane walks after its part, beyond the ring's seam
  bool has_rest[kLanes] = {};

  const FreeWalk* walks = nullptr;
  size_t walk_count = 0;
  size_t next_walk = 0;
  FreeSpaceMap map{};

  /// Puts a walk into lane l, up to the ring buffer's seam or the map's edge.
  void load(int l, FreeWalk w) {
    has_rest[l] = cut_at_seam(w, rest[l], map);
    const int32_t brick_stride[3] = {1, map.bricks[0], map.bricks[0] * map.bricks[1]};
    int32_t in_brick = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const int32_t s = w.step[axis];
      next[axis][l] = w.t_next[axis];
      delta[axis][l] = w.t_delta[axis];
      move[axis][l] = s * (1 << axis * kFieldBits);
      forward[axis][l] = s * brick_stride[axis];
      in_brick |= (w.offset[axis] & (kBrickSize - 1)) << axis * kFieldBits;
    }
    place[l] = in_brick | kPlaceBias;
    left[l] = w.turns;
    low[l] = 0;
    high[l] = 0;
    brick[l] = map.brick_of(w.offset);
  }

  /// Gives every idle lane the rest of its walk or the next walk; false where no lane has one.
  bool refill() {
    bool any = false;
    for (int l = 0; l < kLanes; ++l) {
      if (left[l] <= 0) {
        if (has_rest[l]) {
          load(l, rest[l]);
        } else if (next_walk < walk_count) {
          load(l, walks[next_walk++]);
        }
      }
      any = any || left[l] > 0;
    }
    return any;
  }

  bool walk_avx2(FreeSpaceLanes::Words& out);
};

namespace {
/// For each mask of 8 lanes, the lanes it names, first to last: where a compressed store
/// takes its values from.
struct CompressTable {
  alignas(32) int32_t lanes[256][kLanes];
  CompressTable() : lanes{} {
    for (int mask = 0; mask < 256; ++mask) {
      int k = 0;
      for (int l = 0; l < kLanes; ++l) {
        if ((mask >> l) & 1) lanes[mask][k++] = l;
      }
    }
  }
};
const CompressTable kCompress;
}  // namespace

#if FEATSENSE_FREE_SPACE_LANES_AVX2
namespace {
// A row of the state as a vector, and back (lambdas would not take the function's target).
__attribute__((target("avx2"), always_inline)) inline __m256i row(const int32_t* p) {
  return _mm256_load_si256(reinterpret_cast<const __m256i*>(p));
}
__attribute__((target("avx2"), always_inline)) inline void put(int32_t* p, __m256i v) {
  _mm256_store_si256(reinterpret_cast<__m256i*>(p), v);
}
}  // namespace

__attribute__((target("avx2,popcnt"))) bool FreeSpaceLanes::State::walk_avx2(
    FreeSpaceLanes::Words& out) {
  size_t out_count = 0;
  int32_t* const out_word = out.word.data();
  uint32_t* const out_low = out.low.data();
  uint32_t* const out_high = out.high.data();
  const __m256i zero = _mm256_setzero_si256();
  const __m256i one = _mm256_set1_epi32(1);
  const __m256i seven = _mm256_set1_epi32(kBrickSize - 1);
  const __m256i thirty_two = _mm256_set1_epi32(32);
  const __m256i place_low = _mm256_set1_epi32(kPlaceLow);
  const __m256i place_bias = _mm256_set1_epi32(kPlaceBias);
  const __m256i place_guard = _mm256_set1_epi32(kPlaceGuard);
  const __m256i y_bits = _mm256_set1_epi32(7 << 3);
  for (;;) {
    out.count = out_count;
    if (!refill()) return false;
    __m256i nx = row(next[0]), ny = row(next[1]), nz = row(next[2]);
    const __m256i dx = row(delta[0]), dy = row(delta[1]), dz = row(delta[2]);
    __m256i pl = row(place), lf = row(left), lo = row(low), hi = row(high), br = row(brick);
    const __m256i mvx = row(move[0]), mvy = row(move[1]), mvz = row(move[2]);
    const __m256i fwx = row(forward[0]), fwy = row(forward[1]), fwz = row(forward[2]);
    bool full = false;
    for (;;) {
      const __m256i active = _mm256_cmpgt_epi32(lf, zero);
      // The current voxel's bit, x + 8 y (a shift by 32 or more gives 0: the other half's).
      const __m256i bit = _mm256_or_si256(_mm256_and_si256(pl, seven),
                                          _mm256_and_si256(_mm256_srli_epi32(pl, 2), y_bits));
      lo = _mm256_or_si256(lo, _mm256_sllv_epi32(one, bit));
      hi = _mm256_or_si256(hi, _mm256_sllv_epi32(one, _mm256_sub_epi32(bit, thirty_two)));
      const __m256i ended = _mm256_cmpeq_epi32(lf, one);
      lf = _mm256_sub_epi32(lf, one);
      // The step rule: the nearest crossing, the lower axis on ties.
      const __m256i y_first = _mm256_cmpgt_epi32(nx, ny);
      const __m256i along_z = _mm256_cmpgt_epi32(_mm256_min_epi32(nx, ny), nz);
      const __m256i along_y = _mm256_andnot_si256(along_z, y_first);
      const __m256i along_x = _mm256_cmpeq_epi32(_mm256_or_si256(along_z, y_first), zero);
      nx = _mm256_add_epi32(nx, _mm256_and_si256(dx, along_x));
      ny = _mm256_add_epi32(ny, _mm256_and_si256(dy, along_y));
      nz = _mm256_add_epi32(nz, _mm256_and_si256(dz, along_z));
      // The step, and whether it left the brick.
      const __m256i moved = _mm256_add_epi32(
          pl, _mm256_blendv_epi8(_mm256_blendv_epi8(mvx, mvy, along_y), mvz, along_z));
      const __m256i inside = _mm256_cmpeq_epi32(_mm256_and_si256(moved, place_guard), place_bias);
      // A word is done where the walk ends, steps along z or leaves the brick.
      const __m256i done_word =
          _mm256_andnot_si256(_mm256_andnot_si256(_mm256_or_si256(ended, along_z), inside), active);
      const __m256i z = _mm256_and_si256(_mm256_srli_epi32(pl, 2 * kFieldBits), seven);
      const __m256i word = _mm256_add_epi32(_mm256_slli_epi32(br, 3), z);
      const int mask = _mm256_movemask_ps(_mm256_castsi256_ps(done_word));
      const __m256i pick = row(kCompress.lanes[mask]);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(&out_word[out_count]),
                          _mm256_permutevar8x32_epi32(word, pick));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(&out_low[out_count]),
                          _mm256_permutevar8x32_epi32(lo, pick));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(&out_high[out_count]),
                          _mm256_permutevar8x32_epi32(hi, pick));
      out_count += static_cast<size_t>(__builtin_popcount(static_cast<unsigned>(mask)));
      lo = _mm256_andnot_si256(done_word, lo);
      hi = _mm256_andnot_si256(done_word, hi);
      pl = _mm256_or_si256(_mm256_and_si256(moved, place_low), place_bias);
      // Out of the brick: one stride on (a part never crosses the ring's seam).
      br = _mm256_add_epi32(
          br, _mm256_andnot_si256(
                  inside, _mm256_blendv_epi8(_mm256_blendv_epi8(fwx, fwy, along_y), fwz, along_z)));
      full = out_count + kLanes > kWordCapacity;
      if ((_mm256_movemask_ps(_mm256_castsi256_ps(ended)) != 0) | full) break;
    }
    put(next[0], nx), put(next[1], ny), put(next[2], nz);
    put(place, pl), put(left, lf), put(low, lo), put(high, hi), put(brick, br);
    if (full) {
      out.count = out_count;
      return true;
    }
  }
}
#else
bool FreeSpaceLanes::State::walk_avx2(FreeSpaceLanes::Words&) { return false; }
#endif

bool FreeSpaceLanes::supported() { return FEATSENSE_FREE_SPACE_LANES_AVX2 && cpu_has_avx2(); }

FreeSpaceLanes::FreeSpaceLanes() : state_(std::make_unique<State>()) {
  out_.word.resize(kWordCapacity + kLanes);
  out_.low.resize(kWordCapacity + kLanes);
  out_.high.resize(kWordCapacity + kLanes);
}
FreeSpaceLanes::~FreeSpaceLanes() = default;
FreeSpaceLanes::FreeSpaceLanes(FreeSpaceLanes&&) noexcept = default;
FreeSpaceLanes& FreeSpaceLanes::operator=(FreeSpaceLanes&&) noexcept = default;

void FreeSpaceLanes::start(const FreeWalk* walks, size_t count, const FreeSpaceMap& map) {
  State& s = *state_;
  for (int l = 0; l < kLanes; ++l) {
    s.left[l] = 0;
    s.has_rest[l] = false;
  }
  s.walks = walks;
  s.walk_count = count;
  s.next_walk = 0;
  s.map = map;
  out_.count = 0;
}

bool FreeSpaceLanes::walk() { return state_->walk_avx2(out_); }

}  // namespace featsense::tsdf::detail
