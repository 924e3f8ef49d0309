#pragma once
// A map for benchmarks: the exact TSDF of a furnished hall, written as a scanner would leave
// it (free space observed, nothing more than tau behind a surface).

#include <Eigen/Core>

#include "featsense/storage/memory_chunk_store.hpp"

namespace featsense::bench {

/// A hall of `size_m` (x, y, z; centred on the origin in x and y, floor at z = -2 m so that
/// chunk coordinates are negative too) with pillars, tables, crates and balls, voxels of
/// `voxel_size_m`, weight 4 measurements everywhere observed. Built in parallel (TBB).
storage::MemoryChunkStore make_hall_map(const Eigen::Vector3d& size_m, double voxel_size_m,
                                        double truncation_m);

}  // namespace featsense::bench
