#pragma once
// A map wider than one chunk in x and y (negative chunk coordinates too), for the tiling
// tests: rolling ground with a ball resting across chunk borders.

#include <algorithm>
#include <cmath>

#include "mesh/tsdf_test_fields.hpp"

namespace featsense::test {

constexpr double kTileSceneVoxel = 0.05;  ///< chunks of 3.2 m
constexpr double kTileSceneTau = 0.15;

/// Voxels -100 .. 99 in x and y (chunks -2 .. 1), -30 .. 29 in z.
inline storage::MemoryChunkStore tile_scene_store() {
  storage::MemoryChunkStore store(test_metadata(kTileSceneVoxel, kTileSceneTau));
  const Eigen::Vector3d ball(0.2, -0.1, -0.2);
  write_field(store, Eigen::Vector3i(-100, -100, -30), Eigen::Vector3i(99, 99, 29),
              [&](const Eigen::Vector3d& p) {
                const double ground =
                    p.z() - (-1.0 + 0.2 * std::sin(p.x()) + 0.1 * std::cos(1.3 * p.y()));
                return std::min(ground, sphere_distance(p, ball, 0.9));
              });
  return store;
}

}  // namespace featsense::test
