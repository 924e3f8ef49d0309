// The CPU integrator: one scan in phases, each spread over the threads (TBB): the rays to walk
// (the first end point of each voxel), the walks of each sector's rays, which write the
// per-scan minimum of their own sector's voxels (plain stores, no compare-exchange) and hand
// the others over (cpu_sectors.cpp), then each sector's fusion of the bricks it owns
// (cpu_fusion.cpp). Free-space candidates pass settled free space by (voxel.hpp,
// settled_free_voxel), found in a bit per voxel. What exists only for speed lies in cpu_fast/.
// The same map as the reference integrator (reference_integrator.cpp), bit for bit.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <limits>
#include <memory>

#include "brick_checks.hpp"
#include "cpu_integrator.hpp"

namespace featsense::tsdf {
namespace detail {
namespace {

/// Lowers `slot` to `value` if that is smaller; returns the value it held before.
uint32_t atomic_min(std::atomic<uint32_t>& slot, uint32_t value) {
  uint32_t current = slot.load(std::memory_order_relaxed);
  while (value < current &&
         !slot.compare_exchange_weak(current, value, std::memory_order_relaxed)) {
  }
  return current;
}

}  // namespace

CpuIntegrator::CpuIntegrator(const TsdfSettings& settings, Vec3 centre_m)
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

void CpuIntegrator::read_bricks(const std::vector<Index3>& bricks,
                                std::vector<uint32_t>& voxels) const {
  voxels.resize(bricks.size() * kBrickVoxels);
  for_each_brick(bricks, [&](size_t k, size_t offset) {
    std::copy_n(map_.begin() + static_cast<std::ptrdiff_t>(offset), kBrickVoxels,
                voxels.begin() + static_cast<std::ptrdiff_t>(k * kBrickVoxels));
  });
}

void CpuIntegrator::write_bricks(const std::vector<Index3>& bricks,
                                 const std::vector<uint32_t>& voxels) {
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

void CpuIntegrator::set_origin(Index3 origin) {
  check_brick_aligned(origin);
  geometry_.origin = origin;
}

IntegrationStats CpuIntegrator::integrate(const RayBatch& rays) {
  check_ray_batch(rays);
  const std::vector<uint32_t> kept = rays_to_march(rays);
  if (kept.empty()) return {};
  RayMarchParams params;
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
  free_map_ = FreeSpaceMap::of(geometry_);
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

/// Calls visit(k, storage offset of bricks[k]) for every brick, in parallel.
template <typename Visit>
void CpuIntegrator::for_each_brick(const std::vector<Index3>& bricks, const Visit& visit) const {
  for (const Index3& brick : bricks) check_brick_inside(geometry_, brick);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, bricks.size(), 256),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t k = range.begin(); k != range.end(); ++k) {
                        visit(k, geometry_.brick_offset(bricks[k]));
                      }
                    });
}

/// Indices of the rays to march: all, or the first end point of each voxel of the local
/// map plus every end point outside it (the rule of TsdfSettings::reduce_points_per_voxel,
/// computed as the CUDA backend does: a minimum of point indices per voxel).
std::vector<uint32_t> CpuIntegrator::rays_to_march(const RayBatch& rays) {
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

}  // namespace detail

std::unique_ptr<Integrator> make_cpu_integrator(const TsdfSettings& settings, Vec3 centre_m) {
  return std::make_unique<detail::CpuIntegrator>(settings, centre_m);
}

}  // namespace featsense::tsdf
