// The reference integrator: one scan, step by step, as tsdf/README.md ("One scan") states the
// rule. Everything that makes the other integrators fast (sectors, bits per voxel, jumps across
// settled bricks, free space eight rays at a time, kernels) leaves this result as it is; the
// exactness tests (test/tsdf/test_cpu_integrator_exact.cpp) hold them to it.

#include "featsense/tsdf/reference_integrator.hpp"

#include <algorithm>
#include <unordered_set>

#include "featsense/tsdf/voxel.hpp"
#include "ray_marcher.hpp"

namespace featsense::tsdf {

ReferenceIntegrator::ReferenceIntegrator(const TsdfSettings& settings, Vec3 centre_m)
    : settings_(settings),
      geometry_(centred_geometry(settings, centre_m)),
      map_(geometry_.voxel_count(), kUnobservedVoxel),
      candidates_(geometry_.voxel_count(), kEmptyCandidate) {}

IntegrationStats ReferenceIntegrator::integrate(const RayBatch& rays) {
  check_ray_batch(rays);
  detail::RayMarchParams params;
  params.truncation_m = settings_.truncation_m;
  params.interpolation_slope = settings_.interpolation_slope;
  params.up = rays.up;
  IntegrationStats stats;
  std::unordered_set<size_t> end_voxels;  // voxels that already have their first end point
  std::vector<size_t> touched;            // voxels with a candidate this scan, each once

  for (size_t i = 0; i < rays.size(); ++i) {
    // 1. The rays: with reduce_points_per_voxel, only the first end point (in scan order) of
    //    each voxel of the local map; end points outside the map are all kept.
    Index3 v;
    if (settings_.reduce_points_per_voxel && geometry_.voxel_in_map(rays.endpoints_m[i], v) &&
        !end_voxels.insert(geometry_.linear(v)).second) {
      continue;
    }
    ++stats.rays;
    // 2. The per-scan minimum: the ray proposes a candidate for every voxel it crosses, from
    //    tau behind its end point back to the sensor (or to where its carving starts, sparse
    //    carving), with vertical interpolation near the surface where the ray may interpolate
    //    (march_ray). Each voxel keeps the smallest key (voxel.hpp, make_candidate: measured
    //    beats interpolated, then the smaller |d|, then +d), whatever the order of the rays.
    detail::RayMarchParams ray = params;
    if (!rays.may_interpolate(i)) ray.interpolation_slope = 0.0f;
    ray.carve_from_m = detail::carving_start(settings_.carve_free_space, settings_.dense_range_m,
                                             rays.carving_level_of(i));
    detail::march_ray(rays.origin(i), rays.endpoints_m[i], geometry_, ray,
                      [&](size_t index, int32_t value, bool interpolated) {
                        if (candidates_[index] == kEmptyCandidate) touched.push_back(index);
                        candidates_[index] =
                            std::min(candidates_[index], make_candidate(value, interpolated));
                      });
  }

  const uint32_t settled = settled_free_voxel(settings_.max_weight_fixed());
  for (const size_t index : touched) {
    const uint32_t key = candidates_[index];
    candidates_[index] = kEmptyCandidate;  // ready for the next scan
    const int32_t value = candidate_value(key);
    // 3. Settled free space (+tau at the weight cap) stays as it is where the scan's best
    //    candidate is +tau or interpolated (voxel.hpp, passes_settled_by), and is not counted
    //    as updated.
    if (map_[index] == settled && (value == kValueScale || candidate_interpolated(key))) {
      continue;
    }
    ++stats.voxels_updated;
    // 4. The weight of the winner (full up to a voxel behind the surface, then falling to 0 at
    //    tau behind it) and the fusion, the weighted average in integer arithmetic.
    const uint32_t weight = candidate_weight(value, settings_.falloff_start_fixed());
    map_[index] = pack(fuse(unpack(map_[index]), value, weight, settings_.max_weight_fixed()));
  }
  return stats;
}

}  // namespace featsense::tsdf
