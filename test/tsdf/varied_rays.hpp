#pragma once
// Rays of every kind a walk meets, for the tests that compare a walk with march_ray: along
// diagonals from a brick's corner (ties at every crossing), along an axis, steep ones that
// step along z most, and random ones from around (0, 0, 1.5) that start outside a map
// centred there (which reaches 20 m) or end beyond it.

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "analytic_rays.hpp"
#include "featsense/tsdf/local_map_geometry.hpp"

namespace featsense::tsdf::test {

/// Origin and end point of each ray: 27 fixed ones of `fixed_length_m`, then `random_count`
/// drawn from `random`.
inline std::vector<std::pair<Vec3, Vec3>> varied_rays(float voxel_size_m, float fixed_length_m,
                                                      int random_count, std::mt19937& random) {
  std::vector<std::pair<Vec3, Vec3>> rays;
  const float corner = kBrickSize * voxel_size_m;
  for (const Vec3 origin :
       {make_vec(0, 0, 0), make_vec(corner, corner, corner), make_vec(0.01, -0.02, 1.5)}) {
    for (const Vec3 d : {make_vec(1, 1, 0), make_vec(-1, 1, 0), make_vec(1, 1, 1),
                         make_vec(-1, -1, -1), make_vec(1, 0, 0), make_vec(0, -1, 0.5),
                         make_vec(0.1, 0.2, -1), make_vec(1, 2, 0), make_vec(2, -1, 2)}) {
      rays.emplace_back(origin, origin + (fixed_length_m / norm(d)) * d);
    }
  }
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  for (int k = 0; k < random_count; ++k) {
    const float reach = k % 5 == 0 ? 28.0f : 15.0f;
    const Vec3 origin =
        make_vec(reach * uniform(random), reach * uniform(random), 1.5 + 2.0f * uniform(random));
    const float steepness = k % 4 == 0 ? 2.0f : 0.3f;
    const Vec3 d{uniform(random), uniform(random), steepness * uniform(random)};
    rays.emplace_back(origin, origin + (1.0f + 25.0f * std::fabs(uniform(random))) * d);
  }
  return rays;
}

}  // namespace featsense::tsdf::test
