#pragma once
/// The TSDF rule written as plainly as it goes: the integrator to read first (after voxel.hpp),
/// and the one the exactness tests compare the fast integrators with. One thread, every ray
/// walked voxel by voxel (march_ray, src/ray_marcher.hpp), a plain per-scan minimum in an
/// array of candidates, then the fusion of the voxels the scan touched. Seconds a scan: far too
/// slow for a sensor, which is what the CPU integrator (src/cpu_integrator.cpp) and the CUDA
/// one (cuda/) are for; both give its map bit for bit.

#include <cstdint>
#include <vector>

#include "featsense/tsdf/integrator.hpp"
#include "featsense/tsdf/local_map_geometry.hpp"
#include "featsense/tsdf/ray_batch.hpp"
#include "featsense/tsdf/tsdf_settings.hpp"

namespace featsense::tsdf {

class ReferenceIntegrator {
 public:
  /// An unobserved local map of `settings`, centred on the brick that holds `centre_m`.
  ReferenceIntegrator(const TsdfSettings& settings, Vec3 centre_m);

  /// Fuses one scan, as Integrator::integrate does (the same map, the same stats).
  IntegrationStats integrate(const RayBatch& rays);

  const LocalMapGeometry& geometry() const { return geometry_; }
  /// The local map's packed voxels in ring-buffer order, as Integrator::download gives them.
  const std::vector<uint32_t>& map() const { return map_; }

 private:
  TsdfSettings settings_;
  LocalMapGeometry geometry_;
  std::vector<uint32_t> map_;         ///< packed voxels (voxel.hpp, pack)
  std::vector<uint32_t> candidates_;  ///< the scan's best candidate key per voxel
};

}  // namespace featsense::tsdf
