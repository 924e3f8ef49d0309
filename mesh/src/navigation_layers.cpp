#include "featsense/mesh/navigation_layers.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace featsense::mesh {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

/// Angle between two vectors, degrees; atan2 stays accurate for small angles where acos of
/// a float dot product would give ~0.03 deg of noise.
double angle_deg(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  const Eigen::Vector3d ad = a.cast<double>();
  const Eigen::Vector3d bd = b.cast<double>();
  return std::atan2(ad.cross(bd).norm(), ad.dot(bd)) * kRadToDeg;
}

/// Vertices bucketed by a cubic cell of side `cell_m`, for radius queries.
class VertexGrid {
 public:
  VertexGrid(const std::vector<Eigen::Vector3f>& vertices, double cell_m)
      : vertices_(vertices), cell_m_(cell_m) {
    for (size_t i = 0; i < vertices.size(); ++i) cells_[key(cell_of(vertices[i]))].push_back(i);
  }

  /// Calls visit(j) for every vertex j within `radius_m` of `p` (p's own vertex included).
  template <typename Visit>
  void for_each_within(const Eigen::Vector3f& p, double radius_m, Visit visit) const {
    const Eigen::Vector3i c = cell_of(p);
    const float r2 = static_cast<float>(radius_m * radius_m);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (const size_t j : it->second)
            if ((vertices_[j] - p).squaredNorm() <= r2) visit(j);
        }
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3f& p) const {
    return (p.cast<double>() / cell_m_).array().floor().cast<int>();
  }
  /// 21 bits per axis: cells within +/-1e6 of the origin never collide.
  static uint64_t key(const Eigen::Vector3i& c) {
    const auto part = [](int v) { return static_cast<uint64_t>(v + (1 << 20)) & 0x1FFFFFu; };
    return part(c.x()) << 42 | part(c.y()) << 21 | part(c.z());
  }

  const std::vector<Eigen::Vector3f>& vertices_;
  double cell_m_;
  std::unordered_map<uint64_t, std::vector<size_t>> cells_;
};

}  // namespace

std::vector<Eigen::Vector3f> vertex_normals(const TriangleMesh& mesh) {
  if (mesh.vertices.empty()) throw MeshError("navigation layers: the mesh has no vertices");
  validate(mesh, "navigation mesh");
  if (mesh.has_normals()) return mesh.normals;
  // The unnormalised cross product is twice the face area, so summing it weights by area.
  std::vector<Eigen::Vector3f> normals(mesh.vertices.size(), Eigen::Vector3f::Zero());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3f n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                  .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    for (int k = 0; k < 3; ++k) normals[t[k]] += n;
  }
  for (Eigen::Vector3f& n : normals) {
    const float length = n.norm();
    // A vertex in no face (or only degenerate ones) has no surface direction: treat it as up.
    n = length > 0.0f ? Eigen::Vector3f(n / length) : Eigen::Vector3f::UnitZ();
  }
  return normals;
}

NavigationLayers compute_navigation_layers(const TriangleMesh& mesh,
                                           const NavigationSettings& settings) {
  if (!(settings.max_slope_deg > 0.0) || !(settings.max_step_m > 0.0) ||
      !(settings.radius_m > 0.0)) {
    throw MeshError("navigation layers: max slope, max step and radius must be positive");
  }
  const std::vector<Eigen::Vector3f> normals = vertex_normals(mesh);
  const size_t n = mesh.vertices.size();
  NavigationLayers layers;
  layers.inclination_deg.resize(n);
  layers.roughness_deg.resize(n);
  layers.height_diff_m.resize(n);
  layers.cost.resize(n);

  const VertexGrid grid(mesh.vertices, settings.radius_m);
  // Each vertex's layers depend on the mesh alone: the same values on any number of threads.
  const auto vertex_layers = [&](size_t i, std::vector<size_t>& neighbours) {
    layers.inclination_deg[i] = static_cast<float>(angle_deg(normals[i], Eigen::Vector3f::UnitZ()));
    float z_min = mesh.vertices[i].z();
    float z_max = z_min;
    Eigen::Vector3f normal_sum = Eigen::Vector3f::Zero();
    neighbours.clear();
    grid.for_each_within(mesh.vertices[i], settings.radius_m, [&](size_t j) {
      z_min = std::min(z_min, mesh.vertices[j].z());
      z_max = std::max(z_max, mesh.vertices[j].z());
      normal_sum += normals[j];
      neighbours.push_back(j);
    });
    layers.height_diff_m[i] = z_max - z_min;
    // Roughness: mean deviation of the neighbours' normals from their mean direction.
    const float sum_length = normal_sum.norm();
    double spread = 0.0;
    if (sum_length > 0.0f) {
      const Eigen::Vector3f mean = normal_sum / sum_length;
      for (const size_t j : neighbours) spread += angle_deg(normals[j], mean);
      spread /= static_cast<double>(neighbours.size());
    }
    layers.roughness_deg[i] = static_cast<float>(spread);

    // Cost: the larger of slope and step relative to their limits; 1 at or beyond either.
    const double slope_ratio = layers.inclination_deg[i] / settings.max_slope_deg;
    const double step_ratio = layers.height_diff_m[i] / settings.max_step_m;
    const double ratio = std::max(slope_ratio, step_ratio);
    layers.cost[i] = ratio >= 1.0 ? 1.0f : static_cast<float>(ratio);
  };
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<size_t>& range) {
                      std::vector<size_t> neighbours;
                      for (size_t i = range.begin(); i != range.end(); ++i)
                        vertex_layers(i, neighbours);
                    });

  layers.lethal_faces.resize(mesh.triangles.size());
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const Eigen::Vector3i& t = mesh.triangles[f];
    layers.lethal_faces[f] =
        layers.cost[t[0]] >= 1.0f || layers.cost[t[1]] >= 1.0f || layers.cost[t[2]] >= 1.0f;
  }
  return layers;
}

}  // namespace featsense::mesh
