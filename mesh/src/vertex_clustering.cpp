#include "featsense/mesh/vertex_clustering.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace featsense::mesh {
namespace {

using Triangle = std::array<uint32_t, 3>;

/// The cell of a point, packed into one key: 21 bits per axis cover 2 M cells each way.
uint64_t cell_key(const Eigen::Vector3f& p, const Eigen::Vector3f& lo, double cell_m) {
  const auto axis = [&](int k) {
    return static_cast<uint64_t>(std::floor((p[k] - lo[k]) / cell_m)) & 0x1FFFFFu;
  };
  return axis(0) | (axis(1) << 21) | (axis(2) << 42);
}

/// The same corners in the same cyclic order, smallest first, so that repeats compare equal
/// while the two sides of a thin wall (opposite orders) both stay.
Triangle canonical(uint32_t a, uint32_t b, uint32_t c) {
  if (a <= b && a <= c) return {a, b, c};
  if (b <= a && b <= c) return {b, c, a};
  return {c, a, b};
}

ClusteredMesh cluster_with_cell(const TriangleMesh& mesh, const Eigen::Vector3f& lo,
                                double cell_m) {
  ClusteredMesh result;
  result.cell_size_m = cell_m;
  result.cluster_of_vertex.resize(mesh.vertices.size());
  std::unordered_map<uint64_t, uint32_t> cluster_of_cell;
  cluster_of_cell.reserve(mesh.vertices.size() / 4);
  std::vector<Eigen::Vector3d> sums;
  std::vector<uint32_t> counts;
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    const auto [it, added] = cluster_of_cell.try_emplace(cell_key(mesh.vertices[v], lo, cell_m),
                                                         static_cast<uint32_t>(sums.size()));
    if (added) {
      sums.emplace_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    result.cluster_of_vertex[v] = it->second;
    sums[it->second] += mesh.vertices[v].cast<double>();
    ++counts[it->second];
  }
  result.mesh.vertices.reserve(sums.size());
  for (size_t c = 0; c < sums.size(); ++c)
    result.mesh.vertices.push_back((sums[c] / counts[c]).cast<float>());

  std::vector<Triangle> triangles;
  triangles.reserve(mesh.triangles.size() / 2);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const uint32_t a = result.cluster_of_vertex[static_cast<size_t>(t[0])];
    const uint32_t b = result.cluster_of_vertex[static_cast<size_t>(t[1])];
    const uint32_t c = result.cluster_of_vertex[static_cast<size_t>(t[2])];
    if (a == b || b == c || a == c) continue;
    triangles.push_back(canonical(a, b, c));
  }
  std::sort(triangles.begin(), triangles.end());
  triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
  result.mesh.triangles.reserve(triangles.size());
  for (const Triangle& t : triangles)
    result.mesh.triangles.emplace_back(static_cast<int>(t[0]), static_cast<int>(t[1]),
                                       static_cast<int>(t[2]));
  return result;
}

}  // namespace

ClusteredMesh cluster_vertices(const TriangleMesh& mesh, std::size_t max_triangles) {
  if (max_triangles == 0) throw MeshError("vertex clustering: the triangle budget must be > 0");
  validate(mesh, "vertex clustering's input");
  if (mesh.triangles.size() <= max_triangles) {
    ClusteredMesh same;
    same.mesh.vertices = mesh.vertices;
    same.mesh.triangles = mesh.triangles;
    same.cluster_of_vertex.resize(mesh.vertices.size());
    for (size_t v = 0; v < mesh.vertices.size(); ++v)
      same.cluster_of_vertex[v] = static_cast<uint32_t>(v);
    return same;
  }
  Eigen::Vector3f lo;
  Eigen::Vector3f hi;
  mesh.bounds(&lo, &hi);
  // A surface of area A cut into cells of side c has about A / c^2 vertices and twice as many
  // triangles: the first guess. Each retry grows the cell by the excess, plus a margin.
  double cell_m = std::sqrt(2.0 * surface_area_m2(mesh) / static_cast<double>(max_triangles));
  // The grid's 21 bits per axis bound the cell from below.
  const double extent_m = static_cast<double>((hi - lo).maxCoeff());
  cell_m = std::max({cell_m, extent_m / double(0x1FFFFF), 1e-6});
  for (;;) {
    ClusteredMesh clustered = cluster_with_cell(mesh, lo, cell_m);
    if (clustered.mesh.triangles.size() <= max_triangles) return clustered;
    const double excess =
        static_cast<double>(clustered.mesh.triangles.size()) / static_cast<double>(max_triangles);
    cell_m *= std::sqrt(excess) * 1.05;
  }
}

std::vector<float> average_per_cluster(const ClusteredMesh& clustered,
                                       const std::vector<float>& values) {
  const size_t clusters = clustered.mesh.vertices.size();
  std::vector<double> sums(clusters, 0.0);
  std::vector<uint32_t> counts(clusters, 0);
  const size_t n = std::min(values.size(), clustered.cluster_of_vertex.size());
  for (size_t v = 0; v < n; ++v) {
    if (std::isnan(values[v])) continue;
    sums[clustered.cluster_of_vertex[v]] += values[v];
    ++counts[clustered.cluster_of_vertex[v]];
  }
  std::vector<float> means(clusters, std::numeric_limits<float>::quiet_NaN());
  for (size_t c = 0; c < clusters; ++c)
    if (counts[c] > 0) means[c] = static_cast<float>(sums[c] / counts[c]);
  return means;
}

}  // namespace featsense::mesh
