#pragma once
/// The key of a voxel in a hash map, for the voxel grids of the registration and the
/// localizer: 21 bits per axis, unique within +/- 2^20 voxels of the origin (a million voxels:
/// 100 km at 0.1 m).

#include <Eigen/Core>

#include <cmath>
#include <cstdint>

namespace featsense::slam::refine {

/// The key of voxel (x, y, z).
inline uint64_t voxel_key(int64_t x, int64_t y, int64_t z) {
  constexpr uint64_t mask = (uint64_t{1} << 21) - 1;
  return ((static_cast<uint64_t>(x) & mask) << 42) | ((static_cast<uint64_t>(y) & mask) << 21) |
         (static_cast<uint64_t>(z) & mask);
}

/// The key of the voxel holding `p`, voxels 1 / `inverse_voxel` across; computed in `Scalar`.
template <typename Scalar>
uint64_t voxel_key_of(const Eigen::Matrix<Scalar, 3, 1>& p, Scalar inverse_voxel) {
  const auto axis = [&](Scalar v) { return static_cast<int64_t>(std::floor(v * inverse_voxel)); };
  return voxel_key(axis(p.x()), axis(p.y()), axis(p.z()));
}

}  // namespace featsense::slam::refine
