#pragma once
// Moving the map (Integrator::read_bricks, write_bricks): whole bricks copied between the map
// and a dense staging array, the settled bits renewed for the bricks written. Included by
// cuda_integrator.cu only.

#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>

#include "featsense/tsdf/local_map_geometry.hpp"
#include "kernel_common.cuh"

namespace featsense::tsdf::cuda {

/// One block per brick, one thread per voxel: copies whole bricks between the map (at
/// their storage offsets) and a dense staging array (brick after brick).
__global__ void gather_bricks_kernel(const uint32_t* map, const uint64_t* offsets,
                                     uint32_t* staging) {
  staging[static_cast<size_t>(blockIdx.x) * kBrickVoxels + threadIdx.x] =
      map[offsets[blockIdx.x] + threadIdx.x];
}

__global__ void scatter_bricks_kernel(const uint32_t* staging, const uint64_t* offsets,
                                      uint32_t* map, uint32_t* settled, uint8_t* settled_bricks,
                                      uint32_t settled_voxel) {
  const size_t index = offsets[blockIdx.x] + threadIdx.x;
  const uint32_t voxel = staging[static_cast<size_t>(blockIdx.x) * kBrickVoxels + threadIdx.x];
  map[index] = voxel;
  write_warp_bits(settled, index, voxel == settled_voxel);
  const int all_settled = __syncthreads_and(voxel == settled_voxel);
  if (threadIdx.x == 0) settled_bricks[offsets[blockIdx.x] / kBrickVoxels] = all_settled != 0;
}

}  // namespace featsense::tsdf::cuda
