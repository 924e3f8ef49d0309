// The reference integrator: rays in parallel with TBB, each thread writing the per-scan
// minimum of the voxels of its own sectors around the sensor (plain stores, no
// compare-exchange), fusion over the voxels this scan touched. Free-space candidates pass
// settled free space by (voxel.hpp, settled_free_voxel), found in a bit per voxel.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>

#include "brick_checks.hpp"
#include "cpu_fast/free_space_fusion.hpp"
#include "cpu_fast/free_space_lanes.hpp"
#include "cpu_fast/free_word_cache.hpp"
#include "cpu_fast/huge_page_allocator.hpp"
#include "featsense/tsdf/integrator.hpp"
#include "ray_walk.hpp"

namespace featsense::tsdf {
namespace {

/// Lowers `slot` to `value` if that is smaller; returns the value it held before.
uint32_t atomic_min(std::atomic<uint32_t>& slot, uint32_t value) {
  uint32_t current = slot.load(std::memory_order_relaxed);
  while (value < current &&
         !slot.compare_exchange_weak(current, value, std::memory_order_relaxed)) {
  }
  return current;
}

class CpuIntegrator final : public Integrator {
 public:
  CpuIntegrator(const TsdfSettings& settings, Vec3 centre_m)
      : settings_(settings),
        geometry_(centred_geometry(settings, centre_m)),
        map_(geometry_.voxel_count(), kUnobservedVoxel),
        candidates_(geometry_.voxel_count()),
        brick_owner_(geometry_.voxel_count() / kBrickVoxels, 0),
        brick_listed_(geometry_.voxel_count() / kBrickVoxels, 0),
        occupancy_(geometry_.voxel_count() / 64, 0),
        free_space_(geometry_.voxel_count() / 64, 0),
        settled_(geometry_.voxel_count() / 64, 0),
        settled_bricks_(geometry_.voxel_count() / kBrickVoxels, 0),
        settled_voxel_(settled_free_voxel(settings.max_weight_fixed())),
        parts_(sector_count()) {
    for (size_t i = 0; i < geometry_.voxel_count(); ++i) {
      candidates_[i].store(kEmptyCandidate, std::memory_order_relaxed);
    }
    for (Part& part : parts_) {
      part.handed_over.resize(parts_.size());
      part.free_handed_over.resize(parts_.size());
    }
  }

  std::string backend_name() const override { return "cpu"; }
  const LocalMapGeometry& geometry() const override { return geometry_; }
  std::vector<uint32_t> download() const override { return {map_.begin(), map_.end()}; }
  size_t memory_bytes() const override {
    return geometry_.voxel_count() * 2 * sizeof(uint32_t) + 3 * geometry_.voxel_count() / 8 +
           3 * geometry_.voxel_count() / kBrickVoxels;
  }

  void read_bricks(const std::vector<Index3>& bricks,
                   std::vector<uint32_t>& voxels) const override {
    voxels.resize(bricks.size() * kBrickVoxels);
    for_each_brick(bricks, [&](size_t k, size_t offset) {
      std::copy_n(map_.begin() + static_cast<std::ptrdiff_t>(offset), kBrickVoxels,
                  voxels.begin() + static_cast<std::ptrdiff_t>(k * kBrickVoxels));
    });
  }

  void write_bricks(const std::vector<Index3>& bricks,
                    const std::vector<uint32_t>& voxels) override {
    check_brick_voxels(bricks, voxels);
    for_each_brick(bricks, [&](size_t k, size_t offset) {
      std::copy_n(voxels.begin() + static_cast<std::ptrdiff_t>(k * kBrickVoxels), kBrickVoxels,
                  map_.begin() + static_cast<std::ptrdiff_t>(offset));
      for (size_t word = offset / 64; word < (offset + kBrickVoxels) / 64; ++word) {
        uint64_t bits = 0;
        for (size_t bit = 0; bit < 64; ++bit) {
          bits |= static_cast<uint64_t>(map_[word * 64 + bit] == settled_voxel_) << bit;
        }
        settled_[word] = bits;
      }
      note_settled_brick(offset / kBrickVoxels);
    });
  }

  void set_origin(Index3 origin) override {
    check_brick_aligned(origin);
    geometry_.origin = origin;
  }

  IntegrationStats integrate(const RayBatch& rays) override {
    check_ray_batch(rays);
    const std::vector<uint32_t> kept = rays_to_march(rays);
    if (kept.empty()) return {};
    detail::RayMarchParams params;
    params.truncation_m = settings_.truncation_m;
    params.interpolation_slope = settings_.interpolation_slope;
    params.up = rays.up;

    // The map is cut into sectors around the sensor, each brick column owned by one; every
    // ray is walked by the sector of its end point, which writes the voxels it owns directly
    // and hands the few others (near the sensor, where sectors are narrow) to their owners.
    // Nobody ever writes a voxel another task may write at the same time, so there is no
    // locked instruction (a compare-exchange per voxel cost more than the rest of the visit).
    const Vec3 centre = rays.origin(kept.front());
    assign_brick_owners(centre);
    free_map_ = detail::FreeSpaceMap::of(geometry_);
    const std::vector<std::vector<uint32_t>> rays_of = rays_by_sector(rays, kept, centre);
    for (Part& part : parts_) {
      part.touched.clear();
      for (auto& list : part.handed_over) list.clear();
      for (auto& list : part.free_handed_over) list.clear();
    }
    tbb::parallel_for(
        size_t{0}, parts_.size(), [&](size_t p) { march_sector(p, rays, rays_of[p], params); },
        tbb::simple_partitioner());
    // Then each sector's bricks are fused by the task that applied what was handed over to it:
    // they are its own, written by no other task.
    std::vector<size_t> updated(parts_.size());
    tbb::parallel_for(
        size_t{0}, parts_.size(),
        [&](size_t p) {
          take_over(p);
          updated[p] = fuse(parts_[p].touched);
        },
        tbb::simple_partitioner());

    IntegrationStats stats;
    stats.rays = kept.size();
    for (const size_t count : updated) stats.voxels_updated += count;
    return stats;
  }

 private:
  /// Calls visit(k, storage offset of bricks[k]) for every brick, in parallel.
  template <typename Visit>
  void for_each_brick(const std::vector<Index3>& bricks, const Visit& visit) const {
    for (const Index3& brick : bricks) check_brick_inside(geometry_, brick);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, bricks.size(), 256),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t k = range.begin(); k != range.end(); ++k) {
                          visit(k, geometry_.brick_offset(bricks[k]));
                        }
                      });
  }

  // Sectors differ in work (the real OS1-128 frames: 9.7 to 22.5 ms a sector of eight): with
  // eight a thread instead of four, two threads finished their walks 4 ms sooner, for 0.3 ms
  // more of candidates handed over (test/bench/RESULTS.md).
  static constexpr int kSectorsPerThread = 8;
  static constexpr size_t kWordsPerBrick = kBrickVoxels / 64;

  /// A candidate for a voxel of another sector.
  struct HandedOver {
    size_t index;
    uint32_t key;
  };
  /// Free space passed in a 64-voxel word of another sector.
  struct FreeBits {
    size_t word;
    uint64_t bits;
  };
  /// What one sector's task collects while walking its rays.
  struct Part {
    std::vector<uint32_t> touched;                        ///< bricks listed for the fusion
    std::vector<std::vector<HandedOver>> handed_over;     ///< by owning sector
    std::vector<std::vector<FreeBits>> free_handed_over;  ///< by owning sector
    std::vector<detail::FreeWalk> free_walks;             ///< set aside for the lanes
    detail::FreeSpaceLanes lanes;                         ///< which walk them
    detail::FreeWordCache word_cache;                     ///< what they pass, merged
  };

  /// Indices of the rays to march: all, or the first end point of each voxel of the local
  /// map plus every end point outside it (the rule of TsdfSettings::reduce_points_per_voxel,
  /// computed as the CUDA backend does: a minimum of point indices per voxel).
  std::vector<uint32_t> rays_to_march(const RayBatch& rays) {
    std::vector<uint32_t> kept;
    kept.reserve(rays.size());
    if (!settings_.reduce_points_per_voxel) {
      for (size_t i = 0; i < rays.size(); ++i) kept.push_back(static_cast<uint32_t>(i));
      return kept;
    }
    // The storage index of each end point's voxel, or none for points outside the map. The
    // voxels lie all over the map: each loop asks for the one kPointsAhead points on ahead.
    constexpr size_t kOutside = std::numeric_limits<size_t>::max();
    constexpr size_t kPointsAhead = 16;
    std::vector<size_t> end_voxel(rays.size());
    const auto prefetch_ahead = [&](size_t i, size_t end) {
      if (i + kPointsAhead < end && end_voxel[i + kPointsAhead] != kOutside) {
        __builtin_prefetch(&candidates_[end_voxel[i + kPointsAhead]], 1);
      }
    };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 4096),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t i = range.begin(); i != range.end(); ++i) {
                          Index3 v;
                          end_voxel[i] = geometry_.voxel_in_map(rays.endpoints_m[i], v)
                                             ? geometry_.linear(v)
                                             : kOutside;
                        }
                        for (size_t i = range.begin(); i != range.end(); ++i) {
                          prefetch_ahead(i, range.end());
                          if (end_voxel[i] != kOutside) {
                            atomic_min(candidates_[end_voxel[i]], static_cast<uint32_t>(i));
                          }
                        }
                      });
    // A point is the first of its voxel when the voxel holds its index. Only that point resets
    // the voxel; the others of the voxel compare with their own index, which it never holds.
    std::vector<uint8_t> keep(rays.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 4096),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t i = range.begin(); i != range.end(); ++i) {
                          prefetch_ahead(i, range.end());
                          if (end_voxel[i] == kOutside) {
                            keep[i] = 1;
                            continue;
                          }
                          std::atomic<uint32_t>& slot = candidates_[end_voxel[i]];
                          keep[i] = slot.load(std::memory_order_relaxed) == i ? 1 : 0;
                          if (keep[i] != 0) slot.store(kEmptyCandidate, std::memory_order_relaxed);
                        }
                      });
    for (size_t i = 0; i < rays.size(); ++i) {
      if (keep[i] != 0) kept.push_back(static_cast<uint32_t>(i));
    }
    return kept;
  }

  /// Fuses the candidates of the listed bricks into the map, resets them, and returns how
  /// many voxels were updated. Brick by brick, so memory is read in whole cache lines.
  size_t fuse(const std::vector<uint32_t>& bricks) {
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
  void prefetch_bits(size_t brick) const {
    __builtin_prefetch(&occupancy_[brick * kWordsPerBrick]);
    __builtin_prefetch(&free_space_[brick * kWordsPerBrick]);
    __builtin_prefetch(&settled_[brick * kWordsPerBrick]);
  }

  static constexpr size_t kVoxelsPerLine = 64 / sizeof(uint32_t);

  void prefetch_voxels(size_t brick) const {
    for (size_t line = 0; line < kBrickVoxels / kVoxelsPerLine; ++line) {
      __builtin_prefetch(&map_[brick * kBrickVoxels + line * kVoxelsPerLine], 1);
    }
  }

  void prefetch_candidates(size_t brick) const {
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
  size_t fuse_brick(size_t brick, int32_t falloff, uint32_t max_weight) {
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
      settled = detail::fuse_free_space_word(&map_[word * 64], passed_free & ~with_key, settled,
                                             candidate_weight(kValueScale, falloff), max_weight,
                                             settled_voxel_);
      settled_[word] = settled;
      updated += static_cast<size_t>(__builtin_popcountll(with_key | passed_free));
    }
    note_settled_brick(brick);
    return updated;
  }

  /// Marks the brick whose voxels are all settled free space, for the walk to jump across.
  void note_settled_brick(size_t brick) {
    uint64_t all = ~uint64_t{0};
    for (size_t word = brick * kWordsPerBrick; word < (brick + 1) * kWordsPerBrick; ++word) {
      all &= settled_[word];
    }
    settled_bricks_[brick] = all == ~uint64_t{0} ? 1 : 0;
  }

  /// Sectors per thread: enough for the threads to balance their load, few enough that
  /// little is handed over between sectors near the sensor.
  static size_t sector_count() {
    const int threads = tbb::this_task_arena::max_concurrency();
    return static_cast<size_t>(std::clamp(kSectorsPerThread * threads, 4, 255));
  }

  /// The sector of map-frame direction (dx, dy) from the sensor: a monotonic stand-in for
  /// atan2 (the diamond angle, in [0, 4)), cut into equal parts.
  size_t sector_of(float dx, float dy) const {
    const float sum = std::fabs(dx) + std::fabs(dy);
    if (!(sum > 0.0f && sum < std::numeric_limits<float>::infinity())) return 0;
    float angle;
    if (dy >= 0.0f) {
      angle = dx >= 0.0f ? dy / sum : 1.0f - dx / sum;
    } else {
      angle = dx < 0.0f ? 2.0f - dy / sum : 3.0f + dx / sum;
    }
    const auto sector = static_cast<size_t>(angle * static_cast<float>(parts_.size()) / 4.0f);
    return std::min(sector, parts_.size() - 1);
  }

  /// Gives each brick column of the map to the sector of its centre seen from `centre`.
  void assign_brick_owners(Vec3 centre) {
    const Index3 nb = geometry_.bricks();
    const float brick_m = static_cast<float>(kBrickSize) * geometry_.voxel_size_m;
    const size_t layer = static_cast<size_t>(nb.x) * static_cast<size_t>(nb.y);
    for (int32_t j = 0; j < nb.y; ++j) {
      for (int32_t i = 0; i < nb.x; ++i) {
        const int32_t bx = geometry_.origin.x / kBrickSize + i;  // global brick coordinates
        const int32_t by = geometry_.origin.y / kBrickSize + j;
        const auto owner =
            static_cast<uint8_t>(sector_of((static_cast<float>(bx) + 0.5f) * brick_m - centre.x,
                                           (static_cast<float>(by) + 0.5f) * brick_m - centre.y));
        const size_t column = static_cast<size_t>(wrap_index(bx, nb.x)) +
                              static_cast<size_t>(nb.x) * static_cast<size_t>(wrap_index(by, nb.y));
        for (int32_t z = 0; z < nb.z; ++z)
          brick_owner_[column + layer * static_cast<size_t>(z)] = owner;
      }
    }
  }

  /// The rays to march, by the sector of their end point.
  std::vector<std::vector<uint32_t>> rays_by_sector(const RayBatch& rays,
                                                    const std::vector<uint32_t>& kept,
                                                    Vec3 centre) const {
    std::vector<std::vector<uint32_t>> rays_of(parts_.size());
    for (const uint32_t i : kept) {
      const Vec3 e = rays.endpoints_m[i];
      rays_of[sector_of(e.x - centre.x, e.y - centre.y)].push_back(i);
    }
    return rays_of;
  }

  /// A walk's visitor for sector p. Free space, most of every walk, proposes the same key at
  /// every visit (+tau, measured), so the scan's minimum only needs to know which voxels were
  /// passed: their bits are gathered in a register while the walk stays in one 64-voxel word
  /// (8 x 8 voxels of a brick) and then set in free_space_ at once (or handed over), settled
  /// free space left out. A free-space step so touches no memory; the fusion takes
  /// min(candidate, +tau) where a bit is set, as if each visit had proposed +tau.
  struct SectorVisitor {
    static constexpr bool kTakesFreeWalks = true;  // free_walk, below
    CpuIntegrator& self;
    size_t p;
    size_t word = std::numeric_limits<size_t>::max();  // the word being gathered, none yet
    uint64_t bits = 0;

    void operator()(size_t index, int32_t value, bool interpolated) {
      if (value == kValueScale && !interpolated) {
        if (index / 64 != word) {
          flush();
          word = index / 64;
        }
        bits |= uint64_t{1} << (index % 64);
        return;
      }
      self.propose(p, index, value, interpolated);
    }

    void flush() {
      free_word(word, bits);
      bits = 0;
    }

    /// The free space at the end of a walk: set aside for the lanes (free_space_lanes.hpp),
    /// which walk the sector's walks eight at a time when it is done with its rays, or where
    /// the processor can't run them, walked here and now.
    void free_walk(const detail::FreeWalk& walk) {
      if (self.lanes_supported_) {
        self.parts_[p].free_walks.push_back(walk);
      } else {
        detail::walk_free_space_job(walk, self.free_map_, self.settled_bricks_.data(), *this);
      }
    }

    /// Walks the walks set aside, and hands what was gathered over.
    void finish() {
      flush();
      Part& part = self.parts_[p];
      if (part.free_walks.empty()) return;
      part.lanes.start(part.free_walks.data(), part.free_walks.size(), self.free_map_);
      const auto hand_on = [this](size_t passed_word, uint64_t passed) {
        free_word(passed_word, passed);
      };
      bool more = true;
      while (more) {
        more = part.lanes.walk();
        for (size_t k = 0; k < part.lanes.words(); ++k) {
          const auto passed_word = static_cast<size_t>(part.lanes.word(k));
          if (part.word_cache.add(passed_word, part.lanes.bits(k), hand_on)) {
            // Its bit words are seldom cached: asked for now, they are there when it is
            // handed on.
            __builtin_prefetch(&self.settled_[passed_word]);
            __builtin_prefetch(&self.free_space_[passed_word], 1);
          }
        }
      }
      part.word_cache.flush(hand_on);
      part.free_walks.clear();
    }

    /// Free space passed in the voxels of `passed_word` that `passed` names (where free space
    /// comes a word at a time: from the walk's free-space loop, free_space_walk.hpp, or from
    /// the lanes through the word table, finish()).
    void free_word(size_t passed_word, uint64_t passed) {
      if (passed == 0) return;
      const uint64_t fresh = passed & ~self.settled_[passed_word];
      if (fresh == 0) return;
      const uint8_t owner = self.brick_owner_[passed_word / kWordsPerBrick];
      if (owner == p) {
        self.pass_free_space(self.parts_[p], passed_word, fresh);
      } else {
        self.parts_[p].free_handed_over[owner].push_back({passed_word, fresh});
      }
    }
  };

  /// A candidate other than free space from sector p's walks.
  void propose(size_t p, size_t index, int32_t value, bool interpolated) {
    // Settled free space stays as it is (the bits are a cache line a brick, mostly cached).
    if (passes_settled_by(value, interpolated) &&
        ((settled_[index / 64] >> (index % 64)) & 1u) != 0u) {
      return;
    }
    const uint32_t key = make_candidate(value, interpolated);
    // Candidates only fall during a scan: one at or below this key already makes it moot.
    const uint32_t current = candidates_[index].load(std::memory_order_relaxed);
    if (key >= current) return;
    const uint8_t owner = brick_owner_[index / kBrickVoxels];
    if (owner == p) {
      lower(parts_[p], index, key, current);
    } else {
      parts_[p].handed_over[owner].push_back({index, key});
    }
  }

  /// Sector p walks its rays: candidates for its own voxels are written, the others handed over.
  void march_sector(size_t p, const RayBatch& rays, const std::vector<uint32_t>& ray_ids,
                    const detail::RayMarchParams& params) {
    detail::RayMarchParams flat = params;
    flat.interpolation_slope = 0.0f;
    SectorVisitor visit{*this, p};
    for (const uint32_t i : ray_ids) {
      detail::RayMarchParams ray = rays.may_interpolate(i) ? params : flat;
      ray.carve_from_m = detail::carving_start(settings_.carve_free_space, settings_.dense_range_m,
                                               rays.carving_level_of(i));
      detail::walk_ray(rays.origin(i), rays.endpoints_m[i], geometry_, ray, visit,
                       settled_bricks_.data());
    }
    visit.finish();
  }

  /// Sector p applies what the other sectors handed over to it.
  void take_over(size_t p) {
    for (const Part& from : parts_) {
      for (const HandedOver& h : from.handed_over[p]) {
        const uint32_t current = candidates_[h.index].load(std::memory_order_relaxed);
        if (h.key < current) lower(parts_[p], h.index, h.key, current);
      }
      for (const FreeBits& f : from.free_handed_over[p]) pass_free_space(parts_[p], f.word, f.bits);
    }
  }

  /// Free space passed in voxels of `part`'s sector: the bits of one 64-voxel word (see
  /// SectorVisitor). Bits are a cache line a brick.
  void pass_free_space(Part& part, size_t word, uint64_t bits) {
    uint64_t& passed = free_space_[word];
    if ((passed | bits) == passed) return;
    passed |= bits;
    list_brick(part, word / kWordsPerBrick);
  }

  /// Lists a brick for the fusion once.
  void list_brick(Part& part, size_t brick) {
    if (brick_listed_[brick] == 0) {
      brick_listed_[brick] = 1;
      part.touched.push_back(static_cast<uint32_t>(brick));
    }
  }

  /// Writes a smaller candidate to a voxel of `part`'s sector; the brick of a voxel's first
  /// candidate is listed once, for the fusion.
  void lower(Part& part, size_t index, uint32_t key, uint32_t current) {
    candidates_[index].store(key, std::memory_order_relaxed);
    if (current != kEmptyCandidate) return;
    occupancy_[index / 64] |= uint64_t{1} << (index % 64);
    list_brick(part, index / kBrickVoxels);
  }

  TsdfSettings settings_;
  LocalMapGeometry geometry_;
  template <typename T>
  using LargeArray = std::vector<T, detail::HugePageAllocator<T>>;
  LargeArray<uint32_t> map_;
  /// The scan's candidates. Atomic only so that a sector may read a voxel another one writes
  /// (to drop moot candidates); every access is relaxed, plain loads and stores.
  LargeArray<std::atomic<uint32_t>> candidates_;
  std::vector<uint8_t> brick_owner_;     ///< the sector that writes each brick, this scan
  std::vector<uint8_t> brick_listed_;    ///< 1 while a brick is listed for the fusion
  LargeArray<uint64_t> occupancy_;       ///< a bit per voxel that has a candidate
  LargeArray<uint64_t> free_space_;      ///< a bit per voxel passed in free space this scan
  LargeArray<uint64_t> settled_;         ///< a bit per voxel of settled free space
  std::vector<uint8_t> settled_bricks_;  ///< 1 per brick of settled free space only
  uint32_t settled_voxel_;               ///< what such a voxel holds
  std::vector<Part> parts_;              ///< one per sector
  detail::FreeSpaceMap free_map_{};      ///< the map as free-space walks see it, this scan
  const bool lanes_supported_ = detail::FreeSpaceLanes::supported();
};

}  // namespace

std::unique_ptr<Integrator> make_cpu_integrator(const TsdfSettings& settings, Vec3 centre_m) {
  return std::make_unique<CpuIntegrator>(settings, centre_m);
}

}  // namespace featsense::tsdf
