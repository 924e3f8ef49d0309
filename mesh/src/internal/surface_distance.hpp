#pragma once
/// How far apart two surfaces are, measured both ways on vertices and area-uniform samples.

#include <cstdint>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::mesh::internal {

struct SurfaceDistance {
  double max_m = 0.0;
  double mean_m = 0.0;
};

/// Distances from points of `a` (vertices and about `samples` surface samples) to `b` and
/// from points of `b` to `a`; the maximum and the mean over all of them (same samples every
/// run).
SurfaceDistance surface_distance(const TriangleMesh& a, const TriangleMesh& b,
                                 std::size_t samples = 200000);

}  // namespace featsense::mesh::internal
