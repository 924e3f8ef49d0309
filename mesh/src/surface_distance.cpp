#include "internal/surface_distance.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "internal/closest_point_query.hpp"
#include "internal/surface_sampling.hpp"

namespace featsense::mesh::internal {
namespace {

struct Sums {
  double max_m = 0.0;
  double sum_m = 0.0;
  std::size_t count = 0;
};

/// Distances from the vertices (every k-th, at most `samples`) and surface samples of `from`
/// to the surface of `to`.
Sums one_way(const TriangleMesh& from, const TriangleMesh& to, std::size_t samples) {
  if (from.triangles.empty() || to.triangles.empty()) return {};
  std::vector<Eigen::Vector3d> points;
  const std::size_t stride = std::max<std::size_t>(1, from.vertices.size() / samples);
  for (std::size_t v = 0; v < from.vertices.size(); v += stride)
    points.push_back(from.vertices[v].cast<double>());
  const double area = surface_area_m2(from);
  if (area > 0.0) {
    const std::vector<Eigen::Vector3d> sampled =
        sample_surface(from, static_cast<double>(samples) / area, 20261122);
    points.insert(points.end(), sampled.begin(), sampled.end());
  }
  const ClosestPointQuery query(to);
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, points.size()), Sums{},
      [&](const tbb::blocked_range<std::size_t>& range, Sums sums) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const double d = query.closest(points[i]).distance_m;
          sums.max_m = std::max(sums.max_m, d);
          sums.sum_m += d;
          ++sums.count;
        }
        return sums;
      },
      [](Sums a, const Sums& b) {
        a.max_m = std::max(a.max_m, b.max_m);
        a.sum_m += b.sum_m;
        a.count += b.count;
        return a;
      });
}

}  // namespace

SurfaceDistance surface_distance(const TriangleMesh& a, const TriangleMesh& b,
                                 std::size_t samples) {
  const Sums ab = one_way(a, b, samples);
  const Sums ba = one_way(b, a, samples);
  SurfaceDistance distance;
  distance.max_m = std::max(ab.max_m, ba.max_m);
  const std::size_t count = ab.count + ba.count;
  distance.mean_m = count > 0 ? (ab.sum_m + ba.sum_m) / static_cast<double>(count) : 0.0;
  return distance;
}

}  // namespace featsense::mesh::internal
