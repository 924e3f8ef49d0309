#pragma once
// A map chunk's surface as the localizer registers scans to it. The surface is where the
// TSDF crosses zero between two neighbouring voxels that were both observed; each crossing
// becomes a point with the plane covariance that GICP gives a point of a surface (flat along
// it, thin across it), turned to the distance field's gradient there: the map already knows
// its normals, so no neighbour search is needed. The points are summed per cell of a fixed
// grid (the registration's finest voxel), so that a chunk's surface costs tens of kilobytes
// rather than the megabyte of its voxels.

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <vector>

#include "featsense/slam/refine/voxel_gaussians.hpp"
#include "featsense/storage/chunk.hpp"

namespace featsense::mapping {

struct SurfaceSettings {
  double voxel_m = 0.064;      ///< the map's voxel edge
  double truncation_m = 0.25;  ///< the map's tau
  double min_weight = 0.5;     ///< both voxels of a crossing observed at least this much
  double cell_m = 0.25;        ///< the cells the crossings are summed in
  double block_m = 0.5;        ///< the blocks whose being observed is kept
};

/// The crossings of one cell of a chunk: their count, their mean and the mean of their
/// covariances. A cell on a chunk's border has a part in each chunk it spans.
struct SurfaceCell {
  std::array<int32_t, 3> index{};  ///< floor(p / cell_m) of its points
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  std::array<float, 6> covariance{};  ///< xx xy xz yy yz zz
  uint32_t points = 0;
};

/// What the localizer keeps of a chunk: its surface, and where it was observed at all (a
/// scan's point where the map saw free space contradicts it; one where the map saw nothing
/// says nothing).
struct ChunkSurface {
  std::vector<SurfaceCell> cells;
  /// floor(p / block_m) of the blocks holding a voxel observed at least min_weight.
  std::vector<std::array<int32_t, 3>> observed_blocks;
  size_t bytes() const;
};

/// The surface of `chunk` at `key` (crossings between voxels inside the chunk: those across
/// its faces are left out, a sixty-fourth of its surface).
ChunkSurface chunk_surface(const storage::ChunkKey& key, const storage::Chunk& chunk,
                           const SurfaceSettings& settings);

/// A key of a cell or block index, unique within +/- 2^20 of the origin.
uint64_t grid_key(const std::array<int32_t, 3>& index);

/// The index of the cell or block `edge_m` across that holds `p`.
std::array<int32_t, 3> grid_index(const Eigen::Vector3d& p, double edge_m);

/// A cell as voxelized GICP sums it (VoxelGaussians' parts).
slam::refine::VoxelGaussian to_voxel_gaussian(const SurfaceCell& cell);

}  // namespace featsense::mapping
