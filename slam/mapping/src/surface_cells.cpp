#include "surface_cells.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "featsense/slam/refine/voxel_key.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::mapping {
namespace {

constexpr int32_t kN = storage::kChunkSize;

/// GICP's plane: eigenvalues (1, 1, epsilon), the thin one along the normal.
constexpr double kPlaneEpsilon = 1e-3;

struct CellSum {
  Eigen::Vector3d points = Eigen::Vector3d::Zero();
  Eigen::Vector3d normals_outer_diagonal = Eigen::Vector3d::Zero();
  Eigen::Vector3d normals_outer_off = Eigen::Vector3d::Zero();  ///< xy xz yz
  uint32_t count = 0;
};

class ChunkField {
 public:
  ChunkField(const storage::Chunk& chunk, uint32_t min_weight_fixed)
      : chunk_(chunk), min_weight_(min_weight_fixed) {}

  bool observed(int32_t x, int32_t y, int32_t z) const {
    if (x < 0 || y < 0 || z < 0 || x >= kN || y >= kN || z >= kN) return false;
    return tsdf::unpack(chunk_.at(x, y, z)).weight >= min_weight_;
  }
  int32_t value(int32_t x, int32_t y, int32_t z) const {
    return tsdf::unpack(chunk_.at(x, y, z)).value;
  }
  /// The distance field's gradient at an observed voxel, in value units per voxel: central
  /// differences where both neighbours were observed, one-sided where one was.
  Eigen::Vector3d gradient(int32_t x, int32_t y, int32_t z) const {
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    const int32_t at = value(x, y, z);
    for (int axis = 0; axis < 3; ++axis) {
      const int32_t dx = axis == 0, dy = axis == 1, dz = axis == 2;
      const bool plus = observed(x + dx, y + dy, z + dz);
      const bool minus = observed(x - dx, y - dy, z - dz);
      if (plus && minus) {
        g[axis] = 0.5 * (value(x + dx, y + dy, z + dz) - value(x - dx, y - dy, z - dz));
      } else if (plus) {
        g[axis] = value(x + dx, y + dy, z + dz) - at;
      } else if (minus) {
        g[axis] = at - value(x - dx, y - dy, z - dz);
      }
    }
    return g;
  }

 private:
  const storage::Chunk& chunk_;
  uint32_t min_weight_;
};

}  // namespace

uint64_t grid_key(const std::array<int32_t, 3>& i) {
  return slam::refine::voxel_key(i[0], i[1], i[2]);
}

size_t ChunkSurface::bytes() const {
  return sizeof(ChunkSurface) + cells.capacity() * sizeof(SurfaceCell) +
         observed_blocks.capacity() * sizeof(observed_blocks[0]);
}

ChunkSurface chunk_surface(const storage::ChunkKey& key, const storage::Chunk& chunk,
                           const SurfaceSettings& settings) {
  const uint32_t min_weight_fixed =
      std::max<uint32_t>(1u, static_cast<uint32_t>(std::min(
                                 65535.0, std::round(settings.min_weight * tsdf::kWeightScale))));
  const ChunkField field(chunk, min_weight_fixed);
  // Both ends clamped at +tau and -tau: free space meeting the back of a surface, which is no
  // surface. (A jump of more than a voxel is no sign of that: a surface seen at a grazing
  // angle has projective distances that change several times faster than the true one.)
  const int32_t clamped = tsdf::kValueScale - tsdf::kValueScale / 100;
  std::unordered_map<uint64_t, std::pair<std::array<int32_t, 3>, CellSum>> cells;
  const Eigen::Vector3d origin(static_cast<double>(key.x) * kN, static_cast<double>(key.y) * kN,
                               static_cast<double>(key.z) * kN);
  const auto floor_index = [](double metres, double edge) {
    return static_cast<int32_t>(std::floor(metres / edge));
  };
  // The blocks the chunk reaches into, as a dense grid of flags.
  std::array<int32_t, 3> first_block{}, blocks_across{};
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = origin[axis] * settings.voxel_m;
    const double hi = (origin[axis] + kN) * settings.voxel_m;
    first_block[axis] = floor_index(lo, settings.block_m);
    blocks_across[axis] = floor_index(hi, settings.block_m) - first_block[axis] + 1;
  }
  std::vector<uint8_t> observed_block(
      static_cast<size_t>(blocks_across[0]) * blocks_across[1] * blocks_across[2], 0);
  // The block of each voxel's centre along each axis, once per chunk rather than per voxel.
  std::array<std::array<size_t, kN>, 3> block_of{};
  for (int axis = 0; axis < 3; ++axis) {
    for (int32_t i = 0; i < kN; ++i) {
      const double centre = (origin[axis] + (i + 0.5)) * settings.voxel_m;
      block_of[axis][static_cast<size_t>(i)] =
          static_cast<size_t>(floor_index(centre, settings.block_m) - first_block[axis]);
    }
  }
  for (int32_t z = 0; z < kN; ++z) {
    for (int32_t y = 0; y < kN; ++y) {
      for (int32_t x = 0; x < kN; ++x) {
        if (!field.observed(x, y, z)) continue;
        const size_t bx = block_of[0][static_cast<size_t>(x)];
        const size_t by = block_of[1][static_cast<size_t>(y)];
        const size_t bz = block_of[2][static_cast<size_t>(z)];
        observed_block[bx + blocks_across[0] * (by + blocks_across[1] * bz)] = 1;
        const int32_t a = field.value(x, y, z);
        for (int axis = 0; axis < 3; ++axis) {
          const int32_t nx = x + (axis == 0), ny = y + (axis == 1), nz = z + (axis == 2);
          if (!field.observed(nx, ny, nz)) continue;
          const int32_t b = field.value(nx, ny, nz);
          if ((a >= 0) == (b >= 0)) continue;
          if (std::abs(a) >= clamped && std::abs(b) >= clamped) continue;
          const double t = static_cast<double>(a) / static_cast<double>(a - b);
          Eigen::Vector3d normal = field.gradient(x, y, z) + field.gradient(nx, ny, nz);
          const double length = normal.norm();
          if (!(length > 0.0)) continue;
          normal /= length;
          Eigen::Vector3d voxel(x + 0.5, y + 0.5, z + 0.5);
          voxel[axis] += t;
          const Eigen::Vector3d p = (origin + voxel) * settings.voxel_m;
          const std::array<int32_t, 3> index = grid_index(p, settings.cell_m);
          auto& [cell_index, sum] = cells[grid_key(index)];
          cell_index = index;
          sum.points += p;
          sum.normals_outer_diagonal += normal.cwiseProduct(normal);
          sum.normals_outer_off += Eigen::Vector3d(normal.x() * normal.y(), normal.x() * normal.z(),
                                                   normal.y() * normal.z());
          ++sum.count;
        }
      }
    }
  }
  ChunkSurface surface;
  std::vector<SurfaceCell>& out = surface.cells;
  out.reserve(cells.size());
  for (const auto& [k, entry] : cells) {
    const auto& [index, sum] = entry;
    const double n = sum.count;
    const Eigen::Vector3d d = sum.normals_outer_diagonal / n;
    const Eigen::Vector3d o = sum.normals_outer_off / n;
    // The mean of I - (1 - epsilon) n n^T over the cell's crossings.
    const double s = 1.0 - kPlaneEpsilon;
    SurfaceCell cell;
    cell.index = index;
    cell.mean = (sum.points / n).cast<float>();
    cell.covariance = {static_cast<float>(1.0 - s * d.x()), static_cast<float>(-s * o.x()),
                       static_cast<float>(-s * o.y()),      static_cast<float>(1.0 - s * d.y()),
                       static_cast<float>(-s * o.z()),      static_cast<float>(1.0 - s * d.z())};
    cell.points = sum.count;
    out.push_back(cell);
  }
  // Hash order is the library's: sort so that the same chunk always gives the same cells.
  std::sort(out.begin(), out.end(),
            [](const SurfaceCell& l, const SurfaceCell& r) { return l.index < r.index; });
  for (int32_t bz = 0; bz < blocks_across[2]; ++bz) {
    for (int32_t by = 0; by < blocks_across[1]; ++by) {
      for (int32_t bx = 0; bx < blocks_across[0]; ++bx) {
        if (observed_block[static_cast<size_t>(bx + blocks_across[0] *
                                                        (by + blocks_across[1] * bz))] != 0) {
          surface.observed_blocks.push_back(
              {first_block[0] + bx, first_block[1] + by, first_block[2] + bz});
        }
      }
    }
  }
  return surface;
}

std::array<int32_t, 3> grid_index(const Eigen::Vector3d& p, double edge_m) {
  return {static_cast<int32_t>(std::floor(p.x() / edge_m)),
          static_cast<int32_t>(std::floor(p.y() / edge_m)),
          static_cast<int32_t>(std::floor(p.z() / edge_m))};
}

slam::refine::VoxelGaussian to_voxel_gaussian(const SurfaceCell& cell) {
  slam::refine::VoxelGaussian v;
  v.mean = cell.mean.cast<double>();
  const auto& c = cell.covariance;
  v.covariance << c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5];
  v.points = static_cast<int>(cell.points);
  return v;
}

}  // namespace featsense::mapping
