#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh::internal {

/// Area-uniform random points on the triangles: each triangle gets floor(area * density)
/// points plus one more with the probability of the remainder, uniform within it. Same seed,
/// same points.
std::vector<Eigen::Vector3d> sample_surface(const TriangleMesh& mesh, double samples_per_m2,
                                            uint64_t seed);

}  // namespace featsense::mesh::internal
