// The CPU integrator's sectors (cpu_integrator.hpp): the map's brick columns are shared out
// among angular sectors around the sensor, each ray is walked by the sector of its end point,
// which writes the candidates of its own voxels and hands the others to their owners, so that
// no two tasks ever write a voxel at once.

#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "cpu_integrator.hpp"
#include "ray_walk.hpp"

namespace featsense::tsdf::detail {

/// Sectors per thread: enough for the threads to balance their load, few enough that
/// little is handed over between sectors near the sensor.
size_t CpuIntegrator::sector_count() {
  const int threads = tbb::this_task_arena::max_concurrency();
  return static_cast<size_t>(std::clamp(kSectorsPerThread * threads, 4, 255));
}

/// The sector of map-frame direction (dx, dy) from the sensor: a monotonic stand-in for
/// atan2 (the diamond angle, in [0, 4)), cut into equal parts.
inline size_t CpuIntegrator::sector_of(float dx, float dy) const {
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
void CpuIntegrator::assign_brick_owners(Vec3 centre) {
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
std::vector<std::vector<uint32_t>> CpuIntegrator::rays_by_sector(const RayBatch& rays,
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
struct CpuIntegrator::SectorVisitor {
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
  void free_walk(const FreeWalk& walk) {
    if (self.lanes_supported_) {
      self.parts_[p].free_walks.push_back(walk);
    } else {
      walk_free_space_job(walk, self.free_map_, self.settled_bricks_.data(), *this);
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
inline void CpuIntegrator::propose(size_t p, size_t index, int32_t value, bool interpolated) {
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
void CpuIntegrator::march_sector(size_t p, const RayBatch& rays,
                                 const std::vector<uint32_t>& ray_ids,
                                 const RayMarchParams& params) {
  RayMarchParams flat = params;
  flat.interpolation_slope = 0.0f;
  SectorVisitor visit{*this, p};
  for (const uint32_t i : ray_ids) {
    RayMarchParams ray = rays.may_interpolate(i) ? params : flat;
    ray.carve_from_m = carving_start(settings_.carve_free_space, settings_.dense_range_m,
                                     rays.carving_level_of(i));
    walk_ray(rays.origin(i), rays.endpoints_m[i], geometry_, ray, visit, settled_bricks_.data());
  }
  visit.finish();
}

/// Sector p applies what the other sectors handed over to it.
void CpuIntegrator::take_over(size_t p) {
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
inline void CpuIntegrator::pass_free_space(Part& part, size_t word, uint64_t bits) {
  uint64_t& passed = free_space_[word];
  if ((passed | bits) == passed) return;
  passed |= bits;
  list_brick(part, word / kWordsPerBrick);
}

/// Lists a brick for the fusion once.
inline void CpuIntegrator::list_brick(Part& part, size_t brick) {
  if (brick_listed_[brick] == 0) {
    brick_listed_[brick] = 1;
    part.touched.push_back(static_cast<uint32_t>(brick));
  }
}

/// Writes a smaller candidate to a voxel of `part`'s sector; the brick of a voxel's first
/// candidate is listed once, for the fusion.
inline void CpuIntegrator::lower(Part& part, size_t index, uint32_t key, uint32_t current) {
  candidates_[index].store(key, std::memory_order_relaxed);
  if (current != kEmptyCandidate) return;
  occupancy_[index / 64] |= uint64_t{1} << (index % 64);
  list_brick(part, index / kBrickVoxels);
}

}  // namespace featsense::tsdf::detail
