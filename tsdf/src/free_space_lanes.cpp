// Free-space walks eight at a time with AVX2 (free_space_lanes.hpp says why and what).

#include "free_space_lanes.hpp"

#include <array>
#include <vector>

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
/// A count of bricks no walk inside the map reaches (axes never stepped along).
constexpr int32_t kNever = 1 << 30;
}  // namespace

/// The lanes' state, a row of kLanes per quantity (loaded as vectors), and the output.
struct FreeSpaceLanes::State {
  alignas(32) int32_t next[3][kLanes];   ///< the next crossing per axis (ticks)
  alignas(32) int32_t delta[3][kLanes];  ///< ticks between crossings
  alignas(32) int32_t place[kLanes];     ///< the voxel in its brick: (z * 8 + y) * 8 + x
  alignas(32) int32_t left[kLanes];      ///< voxels left to visit; <= 0: no walk
  alignas(32) int32_t low[kLanes];       ///< the word's bits 0-31 gathered so far
  alignas(32) int32_t high[kLanes];      ///< bits 32-63
  alignas(32) int32_t brick[kLanes];     ///< storage brick
  alignas(32) int32_t edge[3][kLanes];   ///< the place along the axis a step leaves the brick from
  alignas(32) int32_t move[3][kLanes];   ///< what a step inside the brick adds to the place
  alignas(32) int32_t cross[3][kLanes];  ///< what a step out of the brick adds to the place
  alignas(32) int32_t forward[3][kLanes];   ///< what a step out of the brick adds to brick
  alignas(32) int32_t wrap_fix[3][kLanes];  ///< added too where the ring buffer wraps
  alignas(32) int32_t to_wrap[3][kLanes];   ///< bricks left along the axis until the wrap
  alignas(32) int32_t to_leave[3][kLanes];  ///< bricks left along the axis inside the map

  const FreeWalk* walks = nullptr;
  size_t walk_count = 0;
  size_t next_walk = 0;
  FreeSpaceMap map{};

  /// Puts a walk into lane l.
  void load(int l, const FreeWalk& w) {
    constexpr int32_t kStride[3] = {1, kBrickSize, kBrickSize * kBrickSize};  // in the brick
    const int32_t brick_stride[3] = {1, map.bricks[0], map.bricks[0] * map.bricks[1]};
    for (int axis = 0; axis < 3; ++axis) {
      const int32_t s = w.step[axis];
      const int32_t nb = map.bricks[axis];
      const int32_t b = w.offset[axis] >> kBrickShift;
      const int32_t raw_slot = map.lowest_slot[axis] + b;
      const int32_t slot = raw_slot >= nb ? raw_slot - nb : raw_slot;
      next[axis][l] = w.t_next[axis];
      delta[axis][l] = w.t_delta[axis];
      edge[axis][l] = s < 0 ? 0 : kBrickSize - 1;
      move[axis][l] = s * kStride[axis];
      cross[axis][l] = s * (kStride[axis] - kBrickSize * kStride[axis]);
      forward[axis][l] = s * brick_stride[axis];
      wrap_fix[axis][l] = -s * nb * brick_stride[axis];
      to_wrap[axis][l] = s > 0 ? nb - 1 - slot : s < 0 ? slot : kNever;
      to_leave[axis][l] = s > 0 ? nb - 1 - b : s < 0 ? b : kNever;
    }
    place[l] = ((w.offset[2] & (kBrickSize - 1)) * kBrickSize + (w.offset[1] & (kBrickSize - 1))) *
                   kBrickSize +
               (w.offset[0] & (kBrickSize - 1));
    left[l] = w.turns;
    low[l] = 0;
    high[l] = 0;
    brick[l] = map.brick_of(w.offset);
  }

  /// Gives every idle lane the next walk; false where no lane has one.
  bool refill() {
    bool any = false;
    for (int l = 0; l < kLanes; ++l) {
      if (left[l] <= 0 && next_walk < walk_count) load(l, walks[next_walk++]);
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
  const __m256i low_six = _mm256_set1_epi32(63);
  const __m256i thirty_two = _mm256_set1_epi32(32);
  for (;;) {
    out.count = out_count;
    if (!refill()) return false;
    __m256i nx = row(next[0]), ny = row(next[1]), nz = row(next[2]);
    const __m256i dx = row(delta[0]), dy = row(delta[1]), dz = row(delta[2]);
    __m256i pl = row(place), lf = row(left), lo = row(low), hi = row(high), br = row(brick);
    const __m256i ex = row(edge[0]), ey = row(edge[1]), ez = row(edge[2]);
    const __m256i mvx = row(move[0]), mvy = row(move[1]), mvz = row(move[2]);
    const __m256i crx = row(cross[0]), cry = row(cross[1]), crz = row(cross[2]);
    const __m256i fwx = row(forward[0]), fwy = row(forward[1]), fwz = row(forward[2]);
    const __m256i wfx = row(wrap_fix[0]), wfy = row(wrap_fix[1]), wfz = row(wrap_fix[2]);
    __m256i twx = row(to_wrap[0]), twy = row(to_wrap[1]), twz = row(to_wrap[2]);
    __m256i tlx = row(to_leave[0]), tly = row(to_leave[1]), tlz = row(to_leave[2]);
    bool full = false;
    for (;;) {
      const __m256i active = _mm256_cmpgt_epi32(lf, zero);
      // The current voxel's bit (a shift by 32 or more gives 0: the other half's).
      const __m256i bit = _mm256_and_si256(pl, low_six);
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
      // Whether the step leaves the brick.
      const __m256i pz = _mm256_srli_epi32(pl, 6);
      const __m256i out_x =
          _mm256_and_si256(along_x, _mm256_cmpeq_epi32(_mm256_and_si256(pl, seven), ex));
      const __m256i out_y = _mm256_and_si256(
          along_y, _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_srli_epi32(pl, 3), seven), ey));
      const __m256i out_z = _mm256_and_si256(along_z, _mm256_cmpeq_epi32(pz, ez));
      // A word is done where the walk ends, steps along z or leaves the brick.
      const __m256i done_word = _mm256_and_si256(
          active, _mm256_or_si256(_mm256_or_si256(ended, along_z), _mm256_or_si256(out_x, out_y)));
      const __m256i word = _mm256_add_epi32(_mm256_slli_epi32(br, 3), pz);
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
      // The place in the brick, in this brick or the next.
      const __m256i moved = _mm256_or_si256(
          _mm256_or_si256(_mm256_and_si256(along_x, _mm256_blendv_epi8(mvx, crx, out_x)),
                          _mm256_and_si256(along_y, _mm256_blendv_epi8(mvy, cry, out_y))),
          _mm256_and_si256(along_z, _mm256_blendv_epi8(mvz, crz, out_z)));
      pl = _mm256_add_epi32(pl, moved);
      // The next brick: one stride on, less the ring buffer's length where it wraps.
      const __m256i wraps_x = _mm256_and_si256(out_x, _mm256_cmpeq_epi32(twx, zero));
      const __m256i wraps_y = _mm256_and_si256(out_y, _mm256_cmpeq_epi32(twy, zero));
      const __m256i wraps_z = _mm256_and_si256(out_z, _mm256_cmpeq_epi32(twz, zero));
      const __m256i brick_step = _mm256_or_si256(
          _mm256_or_si256(_mm256_and_si256(out_x, fwx), _mm256_and_si256(out_y, fwy)),
          _mm256_and_si256(out_z, fwz));
      const __m256i brick_wrap = _mm256_or_si256(
          _mm256_or_si256(_mm256_and_si256(wraps_x, wfx), _mm256_and_si256(wraps_y, wfy)),
          _mm256_and_si256(wraps_z, wfz));
      br = _mm256_add_epi32(br, _mm256_add_epi32(brick_step, brick_wrap));
      // Masks are -1: adding one counts a brick down.
      twx = _mm256_add_epi32(twx, out_x);
      twy = _mm256_add_epi32(twy, out_y);
      twz = _mm256_add_epi32(twz, out_z);
      tlx = _mm256_add_epi32(tlx, out_x);
      tly = _mm256_add_epi32(tly, out_y);
      tlz = _mm256_add_epi32(tlz, out_z);
      // A walk leaves the map once, for good (its axes are monotonic).
      const __m256i left_map = _mm256_and_si256(
          active, _mm256_cmpgt_epi32(zero, _mm256_or_si256(_mm256_or_si256(tlx, tly), tlz)));
      const __m256i finished = _mm256_or_si256(ended, left_map);
      full = out_count + kLanes > kWordCapacity;
      if ((_mm256_movemask_ps(_mm256_castsi256_ps(finished)) != 0) | full) {
        lf = _mm256_andnot_si256(left_map, lf);  // a lane that left the map has no walk
        break;
      }
    }
    put(next[0], nx), put(next[1], ny), put(next[2], nz);
    put(place, pl), put(left, lf), put(low, lo), put(high, hi), put(brick, br);
    put(to_wrap[0], twx), put(to_wrap[1], twy), put(to_wrap[2], twz);
    put(to_leave[0], tlx), put(to_leave[1], tly), put(to_leave[2], tlz);
    if (full) {
      out.count = out_count;
      return true;
    }
  }
}
#else
bool FreeSpaceLanes::State::walk_avx2(FreeSpaceLanes::Words&) { return false; }
#endif

bool FreeSpaceLanes::supported() {
#if FEATSENSE_FREE_SPACE_LANES_AVX2
  static const bool has_avx2 = __builtin_cpu_supports("avx2") != 0;
  return has_avx2;
#else
  return false;
#endif
}

FreeSpaceLanes::FreeSpaceLanes() : state_(std::make_unique<State>()) {
  out_.word.resize(kWordCapacity + kLanes);
  out_.low.resize(kWordCapacity + kLanes);
  out_.high.resize(kWordCapacity + kLanes);
  for (int l = 0; l < kLanes; ++l) state_->left[l] = 0;
}
FreeSpaceLanes::~FreeSpaceLanes() = default;
FreeSpaceLanes::FreeSpaceLanes(FreeSpaceLanes&&) noexcept = default;
FreeSpaceLanes& FreeSpaceLanes::operator=(FreeSpaceLanes&&) noexcept = default;

void FreeSpaceLanes::start(const FreeWalk* walks, size_t count, const FreeSpaceMap& map) {
  State& s = *state_;
  for (int l = 0; l < kLanes; ++l) s.left[l] = 0;
  s.walks = walks;
  s.walk_count = count;
  s.next_walk = 0;
  s.map = map;
  out_.count = 0;
}

bool FreeSpaceLanes::walk() { return state_->walk_avx2(out_); }

}  // namespace featsense::tsdf::detail
