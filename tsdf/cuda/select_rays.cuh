#pragma once
// The rays a scan walks (TsdfSettings::reduce_points_per_voxel): the first end point of each
// voxel of the local map, found as the smallest point index per voxel, and every end point
// outside the map; or every ray. Included by cuda_integrator.cu only.

#include <cuda_runtime.h>

#include <cstdint>

#include "featsense/tsdf/local_map_geometry.hpp"
#include "featsense/tsdf/vec3.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::tsdf::cuda {

/// Phase 1 of the reduction: per voxel of the local map, the smallest index of an end point.
__global__ void mark_first_point_kernel(const Vec3* endpoints, uint32_t n, LocalMapGeometry map,
                                        uint32_t* candidates) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  Index3 v;
  if (map.voxel_in_map(endpoints[i], v)) atomicMin(&candidates[map.linear(v)], i);
}

/// Phase 2: the rays to march (the first point of each voxel, every point outside the map),
/// and the voxels' slots reset for the candidates.
__global__ void select_rays_kernel(const Vec3* endpoints, uint32_t n, LocalMapGeometry map,
                                   uint32_t* candidates, uint32_t* kept, uint32_t* kept_count) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  Index3 v;
  bool keep = true;
  if (map.voxel_in_map(endpoints[i], v)) {
    uint32_t* slot = &candidates[map.linear(v)];
    keep = *slot == i;
    // The winner resets the slot at once: a loser reading it afterwards sees
    // kEmptyCandidate, which is no point index, so it still loses.
    if (keep) *slot = kEmptyCandidate;
  }
  if (keep) kept[atomicAdd(kept_count, 1u)] = i;
}

/// Every ray, where the scan keeps them all.
__global__ void identity_kernel(uint32_t* kept, uint32_t n, uint32_t* kept_count) {
  const uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i == 0) *kept_count = n;
  if (i < n) kept[i] = i;
}

}  // namespace featsense::tsdf::cuda
