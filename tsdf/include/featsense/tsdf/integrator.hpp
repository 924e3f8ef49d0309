#pragma once
/// TSDF integration behind one interface, a CPU reference and a CUDA backend.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/tsdf/local_map_geometry.hpp"
#include "featsense/tsdf/ray_batch.hpp"
#include "featsense/tsdf/tsdf_settings.hpp"

namespace featsense::tsdf {

struct IntegrationStats {
  size_t rays = 0;            ///< rays marched (after the per-voxel reduction)
  size_t voxels_updated = 0;  ///< voxels that got a candidate from this scan
};

class Integrator {
 public:
  virtual ~Integrator() = default;

  /// "cpu" or "cuda".
  virtual std::string backend_name() const = 0;
  /// Fuses one scan: per voxel the best candidate of all rays (voxel.hpp), then the weighted
  /// average into the local map. Rays are clipped to the local map.
  virtual IntegrationStats integrate(const RayBatch& rays) = 0;
  virtual const LocalMapGeometry& geometry() const = 0;
  /// The local map's packed voxels in ring-buffer order (local_map_geometry.hpp).
  virtual std::vector<uint32_t> download() const = 0;
  /// Bytes of memory the two volumes take (device memory for the CUDA backend).
  virtual size_t memory_bytes() const = 0;
};

/// The CPU reference integrator (TBB).
std::unique_ptr<Integrator> make_cpu_integrator(const TsdfSettings& settings, Vec3 centre_m);

/// True when this build has the CUDA backend and a usable GPU is present; else false with
/// the reason in `why`.
bool cuda_backend_available(std::string* why = nullptr);
/// The CUDA integrator; throws std::runtime_error when cuda_backend_available() is false.
std::unique_ptr<Integrator> make_cuda_integrator(const TsdfSettings& settings, Vec3 centre_m);

/// The integrator of `backend`: auto picks cuda when available, else cpu. `why` (if given)
/// receives a sentence saying what was chosen and why, for the log and the report.
std::unique_ptr<Integrator> make_integrator(config::Backend backend, const TsdfSettings& settings,
                                            Vec3 centre_m, std::string* why = nullptr);

}  // namespace featsense::tsdf
