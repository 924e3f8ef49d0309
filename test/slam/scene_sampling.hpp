#pragma once
// Noisy samplings of a scene's surface, as registration tests need them: two independent
// samplings of one place never share a point.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::test {

/// `count` points of the scene's surface within `radius` of `centre`, area-weighted, with
/// Gaussian noise of `sigma` along each axis.
inline std::vector<Eigen::Vector3f> sample_scene(const mesh::TriangleMesh& scene,
                                                 const Eigen::Vector3f& centre, float radius,
                                                 int count, float sigma, uint32_t seed) {
  std::vector<double> cumulative;
  std::vector<size_t> triangles;
  double total = 0.0;
  for (size_t t = 0; t < scene.triangles.size(); ++t) {
    const Eigen::Vector3i& f = scene.triangles[t];
    const Eigen::Vector3f a = scene.vertices[f[0]], b = scene.vertices[f[1]],
                          c = scene.vertices[f[2]];
    if (((a + b + c) / 3.0f - centre).norm() > radius) continue;
    total += 0.5 * static_cast<double>((b - a).cross(c - a).norm());
    cumulative.push_back(total);
    triangles.push_back(t);
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pick(0.0, total);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> noise(0.0f, sigma);
  std::vector<Eigen::Vector3f> points;
  while (static_cast<int>(points.size()) < count) {
    const size_t k = static_cast<size_t>(
        std::lower_bound(cumulative.begin(), cumulative.end(), pick(rng)) - cumulative.begin());
    const Eigen::Vector3i& f = scene.triangles[triangles[std::min(k, triangles.size() - 1)]];
    float r1 = u(rng), r2 = u(rng);
    if (r1 + r2 > 1.0f) {
      r1 = 1.0f - r1;
      r2 = 1.0f - r2;
    }
    const Eigen::Vector3f p = scene.vertices[f[0]] +
                              r1 * (scene.vertices[f[1]] - scene.vertices[f[0]]) +
                              r2 * (scene.vertices[f[2]] - scene.vertices[f[0]]);
    points.push_back(p + Eigen::Vector3f(noise(rng), noise(rng), noise(rng)));
  }
  return points;
}

/// The scene around a sensor at its true pose `T` (map <- sensor), in the sensor's frame: a
/// fresh noisy sampling within 40 m, as many points as a keyframe keeps of an outdoor scan
/// (one per 0.4 m voxel), or `count`.
inline std::vector<Eigen::Vector3f> keyframe_scan_at(const mesh::TriangleMesh& scene,
                                                     const Eigen::Isometry3d& T, uint32_t seed,
                                                     int count = 6000) {
  std::vector<Eigen::Vector3f> points =
      sample_scene(scene, T.translation().cast<float>(), 40.0f, count, 0.02f, seed);
  const Eigen::Isometry3d T_sensor_map = T.inverse();
  for (Eigen::Vector3f& p : points) p = (T_sensor_map * p.cast<double>()).cast<float>();
  return points;
}

}  // namespace featsense::test
