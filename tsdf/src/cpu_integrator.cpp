// The reference integrator: rays in parallel with TBB, the per-scan minimum by a
// compare-exchange loop, fusion over the voxels this scan touched.

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <memory>

#include "featsense/tsdf/integrator.hpp"
#include "ray_marcher.hpp"

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
        candidates_(new std::atomic<uint32_t>[geometry_.voxel_count()]) {
    for (size_t i = 0; i < geometry_.voxel_count(); ++i) {
      candidates_[i].store(kEmptyCandidate, std::memory_order_relaxed);
    }
  }

  std::string backend_name() const override { return "cpu"; }
  const LocalMapGeometry& geometry() const override { return geometry_; }
  std::vector<uint32_t> download() const override { return map_; }
  size_t memory_bytes() const override { return geometry_.voxel_count() * 2 * sizeof(uint32_t); }

  IntegrationStats integrate(const RayBatch& rays) override {
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
                          // Only the ray that first fills a slot lists it: each voxel fuses once.
                          if (atomic_min(candidates_[index], key) == kEmptyCandidate) {
                            touched.push_back(static_cast<uint32_t>(index));
                          }
                        };
                        for (size_t k = range.begin(); k != range.end(); ++k) {
                          const size_t i = kept[k];
                          detail::march_ray(rays.origin(i), rays.endpoints_m[i], geometry_, params,
                                            propose);
                        }
                      });

    IntegrationStats stats;
    stats.rays = kept.size();
    for (const std::vector<uint32_t>& list : touched_) {
      stats.voxels_updated += list.size();
      fuse(list);
    }
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
                          const Index3 v = geometry_.voxel_of(rays.endpoints_m[i]);
                          if (geometry_.contains(v)) {
                            atomic_min(candidates_[geometry_.linear(v)], static_cast<uint32_t>(i));
                          }
                        }
                      });
    for (size_t i = 0; i < rays.size(); ++i) {
      const Index3 v = geometry_.voxel_of(rays.endpoints_m[i]);
      if (!geometry_.contains(v)) {
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

  void fuse(const std::vector<uint32_t>& touched) {
    const uint32_t max_weight = settings_.max_weight_fixed();
    const int32_t falloff = settings_.falloff_start_fixed();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, touched.size(), 4096),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t k = range.begin(); k != range.end(); ++k) {
                          const uint32_t index = touched[k];
                          const uint32_t key = candidates_[index].exchange(
                              kEmptyCandidate, std::memory_order_relaxed);
                          const int32_t value = candidate_value(key);
                          map_[index] =
                              pack(tsdf::fuse(unpack(map_[index]), value,
                                              candidate_weight(value, falloff), max_weight));
                        }
                      });
  }

  TsdfSettings settings_;
  LocalMapGeometry geometry_;
  std::vector<uint32_t> map_;
  std::unique_ptr<std::atomic<uint32_t>[]> candidates_;
  tbb::enumerable_thread_specific<std::vector<uint32_t>> touched_;
};

}  // namespace

std::unique_ptr<Integrator> make_cpu_integrator(const TsdfSettings& settings, Vec3 centre_m) {
  return std::make_unique<CpuIntegrator>(settings, centre_m);
}

}  // namespace featsense::tsdf
