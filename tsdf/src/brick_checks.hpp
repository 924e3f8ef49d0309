#pragma once
// Argument checks of the brick access of both backends (integrator.hpp), so that a wrong
// call fails with a message instead of writing outside the map.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "featsense/tsdf/local_map_geometry.hpp"

namespace featsense::tsdf {

inline std::string to_string(Index3 v) {
  return "(" + std::to_string(v.x) + ", " + std::to_string(v.y) + ", " + std::to_string(v.z) + ")";
}

inline void check_brick_inside(const LocalMapGeometry& geometry, Index3 brick) {
  if (!geometry.contains_brick(brick)) {
    throw std::out_of_range("brick " + to_string(brick) + " is outside the local map at origin " +
                            to_string(geometry.origin));
  }
}

inline void check_brick_voxels(const std::vector<Index3>& bricks,
                               const std::vector<uint32_t>& voxels) {
  if (voxels.size() != bricks.size() * static_cast<size_t>(kBrickVoxels)) {
    throw std::invalid_argument("write_bricks: " + std::to_string(voxels.size()) + " voxels for " +
                                std::to_string(bricks.size()) + " bricks");
  }
}

inline void check_brick_aligned(Index3 origin) {
  if (origin.x % kBrickSize != 0 || origin.y % kBrickSize != 0 || origin.z % kBrickSize != 0) {
    throw std::invalid_argument("local map origin " + to_string(origin) +
                                " is not a multiple of the brick size");
  }
}

}  // namespace featsense::tsdf
