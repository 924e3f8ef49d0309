#include "internal/surface_sampling.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace featsense::mesh::internal {

std::vector<Eigen::Vector3d> sample_surface(const TriangleMesh& mesh, double samples_per_m2,
                                            uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Eigen::Vector3d> samples;
  for (const Eigen::Vector3i& tri : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[static_cast<size_t>(tri[0])].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[static_cast<size_t>(tri[1])].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[static_cast<size_t>(tri[2])].cast<double>();
    const double expected = 0.5 * (b - a).cross(c - a).norm() * samples_per_m2;
    double whole = std::floor(expected);
    if (uniform(random) < expected - whole) whole += 1.0;
    for (auto k = static_cast<long>(whole); k > 0; --k) {
      // Uniform in the triangle: fold the unit square's upper half onto the lower one.
      double u = uniform(random);
      double v = uniform(random);
      if (u + v > 1.0) {
        u = 1.0 - u;
        v = 1.0 - v;
      }
      samples.push_back(a + u * (b - a) + v * (c - a));
    }
  }
  return samples;
}

}  // namespace featsense::mesh::internal
