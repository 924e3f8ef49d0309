// The reference integrator: rays in parallel with TBB, the per-scan minimum by a
// compare-exchange loop, fusion over the voxels this scan touched.

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <memory>

#include "cpu_ray_walk.hpp"
#include "featsense/tsdf/integrator.hpp"

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

/// tsdf::fuse, without its division where the result is known: a voxel never observed, or
/// one that already holds the scan's value (most of the carved free space), keeps the value.
Voxel fuse_voxel(Voxel map, int32_t value, uint32_t weight, uint32_t max_weight_fixed) {
  if (weight != 0u && (map.weight == 0u || map.value == value)) {
    const uint32_t total = map.weight + weight;
    return {static_cast<int16_t>(value),
            static_cast<uint16_t>(total < max_weight_fixed ? total : max_weight_fixed)};
  }
  return fuse(map, value, weight, max_weight_fixed);
}

class CpuIntegrator final : public Integrator {
 public:
  CpuIntegrator(const TsdfSettings& settings, Vec3 centre_m)
      : settings_(settings),
        geometry_(centred_geometry(settings, centre_m)),
        map_(geometry_.voxel_count(), kUnobservedVoxel),
        candidates_(new std::atomic<uint32_t>[geometry_.voxel_count()]),
        brick_flags_(new std::atomic<uint8_t>[geometry_.voxel_count() / kBrickVoxels]) {
    for (size_t i = 0; i < geometry_.voxel_count(); ++i) {
      candidates_[i].store(kEmptyCandidate, std::memory_order_relaxed);
    }
    for (size_t b = 0; b < geometry_.voxel_count() / kBrickVoxels; ++b) {
      brick_flags_[b].store(0, std::memory_order_relaxed);
    }
  }

  std::string backend_name() const override { return "cpu"; }
  const LocalMapGeometry& geometry() const override { return geometry_; }
  std::vector<uint32_t> download() const override { return map_; }
  size_t memory_bytes() const override {
    return geometry_.voxel_count() * 2 * sizeof(uint32_t) + geometry_.voxel_count() / kBrickVoxels;
  }

  IntegrationStats integrate(const RayBatch& rays) override {
    check_ray_batch(rays);
    const std::vector<uint32_t> kept = rays_to_march(rays);
    detail::RayMarchParams params;
    params.truncation_m = settings_.truncation_m;
    params.interpolation_slope = settings_.interpolation_slope;
    params.up = rays.up;

    for (auto& list : touched_) list.clear();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, kept.size(), 64),
                      [&](const tbb::blocked_range<size_t>& range) {
                        std::vector<uint32_t>& touched = touched_.local();
                        const auto propose = [&](size_t index, int32_t value, bool interpolated) {
                          const uint32_t key = make_candidate(value, interpolated);
                          if (atomic_min(candidates_[index], key) != kEmptyCandidate) return;
                          // A voxel's first candidate: list its brick once, for the fusion.
                          const size_t brick = index / kBrickVoxels;
                          if (brick_flags_[brick].load(std::memory_order_relaxed) == 0 &&
                              brick_flags_[brick].exchange(1, std::memory_order_relaxed) == 0) {
                            touched.push_back(static_cast<uint32_t>(brick));
                          }
                        };
                        for (size_t k = range.begin(); k != range.end(); ++k) {
                          const size_t i = kept[k];
                          detail::walk_ray(rays.origin(i), rays.endpoints_m[i], geometry_, params,
                                           propose);
                        }
                      });

    IntegrationStats stats;
    stats.rays = kept.size();
    for (const std::vector<uint32_t>& bricks : touched_) stats.voxels_updated += fuse(bricks);
    return stats;
  }

 private:
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
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 4096),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t i = range.begin(); i != range.end(); ++i) {
                          Index3 v;
                          if (geometry_.voxel_in_map(rays.endpoints_m[i], v)) {
                            atomic_min(candidates_[geometry_.linear(v)], static_cast<uint32_t>(i));
                          }
                        }
                      });
    for (size_t i = 0; i < rays.size(); ++i) {
      Index3 v;
      if (!geometry_.voxel_in_map(rays.endpoints_m[i], v)) {
        kept.push_back(static_cast<uint32_t>(i));
        continue;
      }
      std::atomic<uint32_t>& slot = candidates_[geometry_.linear(v)];
      if (slot.load(std::memory_order_relaxed) == i) {
        kept.push_back(static_cast<uint32_t>(i));
        slot.store(kEmptyCandidate, std::memory_order_relaxed);
      }
    }
    return kept;
  }

  /// Fuses the candidates of the listed bricks into the map, resets them, and returns how
  /// many voxels were updated. Brick by brick, so memory is read in whole cache lines.
  size_t fuse(const std::vector<uint32_t>& bricks) {
    const uint32_t max_weight = settings_.max_weight_fixed();
    const int32_t falloff = settings_.falloff_start_fixed();
    std::atomic<size_t> updated{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, bricks.size(), 16),
                      [&](const tbb::blocked_range<size_t>& range) {
                        size_t local_updated = 0;
                        for (size_t k = range.begin(); k != range.end(); ++k) {
                          const size_t first = static_cast<size_t>(bricks[k]) * kBrickVoxels;
                          for (size_t index = first; index < first + kBrickVoxels; ++index) {
                            const uint32_t key = candidates_[index].load(std::memory_order_relaxed);
                            if (key == kEmptyCandidate) continue;
                            candidates_[index].store(kEmptyCandidate, std::memory_order_relaxed);
                            const int32_t value = candidate_value(key);
                            map_[index] =
                                pack(fuse_voxel(unpack(map_[index]), value,
                                                candidate_weight(value, falloff), max_weight));
                            ++local_updated;
                          }
                          brick_flags_[bricks[k]].store(0, std::memory_order_relaxed);
                        }
                        updated += local_updated;
                      });
    return updated.load();
  }

  TsdfSettings settings_;
  LocalMapGeometry geometry_;
  std::vector<uint32_t> map_;
  std::unique_ptr<std::atomic<uint32_t>[]> candidates_;
  std::unique_ptr<std::atomic<uint8_t>[]> brick_flags_;             ///< 1 while a brick is listed
  tbb::enumerable_thread_specific<std::vector<uint32_t>> touched_;  ///< bricks, per thread
};

}  // namespace

std::unique_ptr<Integrator> make_cpu_integrator(const TsdfSettings& settings, Vec3 centre_m) {
  return std::make_unique<CpuIntegrator>(settings, centre_m);
}

}  // namespace featsense::tsdf
