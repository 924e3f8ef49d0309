#pragma once
// Exact signed distance fields written into a chunk store as a TSDF, for the meshing tests.

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <functional>

#include "featsense/storage/memory_chunk_store.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::test {

/// Signed distance (metres, positive outside) at a point of the map frame.
using DistanceField = std::function<double(const Eigen::Vector3d&)>;
/// Weight (measurements) of the voxel at a point; 0 leaves it unobserved.
using WeightField = std::function<double(const Eigen::Vector3d&)>;

inline storage::MapMetadata test_metadata(double voxel_size_m, double truncation_m) {
  storage::MapMetadata metadata;
  metadata.voxel_size_m = voxel_size_m;
  metadata.truncation_m = truncation_m;
  metadata.max_weight = 100.0;
  metadata.sensor = "analytic";
  return metadata;
}

/// Writes the field for global voxels lo .. hi (inclusive) into `store`. Voxels more than tau
/// behind the surface stay unobserved, as a scan leaves them.
inline void write_field(storage::ChunkStore& store, const Eigen::Vector3i& lo,
                        const Eigen::Vector3i& hi, const DistanceField& distance,
                        const WeightField& weight = {}) {
  const double h = store.metadata().voxel_size_m;
  const double tau = store.metadata().truncation_m;
  const storage::ChunkKey first = storage::chunk_of_voxel(lo.x(), lo.y(), lo.z());
  const storage::ChunkKey last = storage::chunk_of_voxel(hi.x(), hi.y(), hi.z());
  for (int32_t cz = first.z; cz <= last.z; ++cz)
    for (int32_t cy = first.y; cy <= last.y; ++cy)
      for (int32_t cx = first.x; cx <= last.x; ++cx) {
        storage::Chunk chunk;
        for (int32_t z = 0; z < storage::kChunkSize; ++z)
          for (int32_t y = 0; y < storage::kChunkSize; ++y)
            for (int32_t x = 0; x < storage::kChunkSize; ++x) {
              const Eigen::Vector3i g(cx * storage::kChunkSize + x, cy * storage::kChunkSize + y,
                                      cz * storage::kChunkSize + z);
              if ((g.array() < lo.array()).any() || (g.array() > hi.array()).any()) continue;
              const Eigen::Vector3d p = (g.cast<double>().array() + 0.5) * h;
              const double d = distance(p);
              if (d < -tau) continue;
              const double w = weight ? weight(p) : 1.0;
              tsdf::Voxel v;
              v.value = static_cast<int16_t>(
                  tsdf::distance_to_fixed(static_cast<float>(d), static_cast<float>(tau)));
              v.weight = static_cast<uint16_t>(std::lround(w * tsdf::kWeightScale));
              chunk.at(x, y, z) = tsdf::pack(v);
            }
        store.write({cx, cy, cz}, chunk);
      }
}

inline double sphere_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& centre,
                              double radius) {
  return (p - centre).norm() - radius;
}

/// Exact distance to the axis-aligned box [lo, hi].
inline double box_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                           const Eigen::Vector3d& hi) {
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const Eigen::Vector3d half = 0.5 * (hi - lo);
  const Eigen::Vector3d q = (p - centre).cwiseAbs() - half;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

}  // namespace featsense::test
