#pragma once
/// TSDF integration behind one interface, a CPU and a CUDA backend; both give the map of the
/// reference integrator (reference_integrator.hpp) bit for bit.

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
  size_t rays = 0;  ///< rays marched (after the per-voxel reduction)
  /// Voxels that got a candidate from this scan; not settled free space passed by
  /// (settled_free_voxel), which the scan leaves as it is.
  size_t voxels_updated = 0;
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

  // Brick access for moving the map (local_map_shift.hpp). A brick is named by its global
  // brick coordinate (global voxel index / kBrickSize) and must lie inside the local map; its
  // kBrickVoxels packed voxels are in brick order, (z * 8 + y) * 8 + x.

  /// Copies the listed bricks into `voxels` (resized to bricks.size() * kBrickVoxels).
  virtual void read_bricks(const std::vector<Index3>& bricks,
                           std::vector<uint32_t>& voxels) const = 0;
  /// Overwrites the listed bricks with `voxels` (bricks.size() * kBrickVoxels of them).
  virtual void write_bricks(const std::vector<Index3>& bricks,
                            const std::vector<uint32_t>& voxels) = 0;
  /// Moves the local map's lowest corner to `origin` (a multiple of kBrickSize) without
  /// touching any voxel: the bricks the old and the new box share keep their voxels, and the
  /// ring-buffer slots of the bricks that left now hold stale voxels for the bricks that
  /// entered. storage::ShiftingMap fills them.
  virtual void set_origin(Index3 origin) = 0;
};

/// The CPU integrator (TBB; src/cpu_integrator.hpp).
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
