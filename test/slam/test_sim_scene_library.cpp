// The built-in scenes: deterministic, their named paths inside them and clear of obstacles,
// foliage made of many small facets.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/scene_library.hpp"

namespace featsense::slam {
namespace {

TEST(SimSceneLibrary, ScenesAreTheSameOnEveryBuild) {
  for (const std::string& name : scene_names()) {
    const mesh::TriangleMesh a = build_scene(name);
    const mesh::TriangleMesh b = build_scene(name);
    ASSERT_GT(a.triangle_count(), 0u) << name;
    ASSERT_EQ(a.vertices.size(), b.vertices.size()) << name;
    for (size_t i = 0; i < a.vertices.size(); ++i) ASSERT_EQ(a.vertices[i], b.vertices[i]) << name;
    EXPECT_EQ(a.triangle_part, b.triangle_part) << name;
  }
}

TEST(SimSceneLibrary, SizesAsSpecified) {
  Eigen::Vector3f lo, hi;
  build_scene("lab").bounds(&lo, &hi);
  EXPECT_FLOAT_EQ(lo.x(), -10.0f);  // the 20 x 20 x 4 m room, the corridor beyond x = 10
  EXPECT_FLOAT_EQ(lo.y(), -10.0f);
  EXPECT_FLOAT_EQ(hi.y(), 10.0f);
  EXPECT_FLOAT_EQ(hi.z(), 4.0f);
  build_scene("parking").bounds(&lo, &hi);
  EXPECT_GE(hi.x() - lo.x(), 90.0f);  // the 90 x 30 m lot and the buildings around it
  EXPECT_GE(hi.y() - lo.y(), 30.0f);
  const mesh::TriangleMesh parking = build_scene("parking");
  size_t foliage = 0;
  for (size_t t = 0; t < parking.triangle_count(); ++t) {
    if (parking.parts[parking.triangle_part[t]].name == "foliage") {
      ++foliage;
      const Eigen::Vector3i& f = parking.triangles[t];
      const float edge = (parking.vertices[static_cast<size_t>(f[1])] -
                          parking.vertices[static_cast<size_t>(f[0])])
                             .norm();
      EXPECT_LT(edge, 0.6f);  // small facets
    }
  }
  EXPECT_GT(foliage, 5000u);
}

/// The vertices of the mesh's triangles of cars (`cars`) or of everything else, in order.
std::vector<Eigen::Vector3f> vertices_of(const mesh::TriangleMesh& m, bool cars) {
  std::vector<Eigen::Vector3f> out;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const std::string& part = m.parts[m.triangle_part[t]].name;
    const bool car = part == "car body" || part == "car window" || part == "tyre";
    if (car != cars) continue;
    for (int k = 0; k < 3; ++k) out.push_back(m.vertices[static_cast<size_t>(m.triangles[t][k])]);
  }
  return out;
}

TEST(SimSceneLibrary, TheTownOnAnotherDayHasOnlyItsParkedCarsMoved) {
  const mesh::TriangleMesh mapped = build_scene("town");
  const mesh::TriangleMesh changed = build_scene("town-changed");
  // Everything but the cars the same, triangle for triangle.
  EXPECT_EQ(vertices_of(mapped, false), vertices_of(changed, false));
  // The cars: about as many (60 % of the bays taken either day), hardly any where they were.
  const std::vector<Eigen::Vector3f> before = vertices_of(mapped, true);
  const std::vector<Eigen::Vector3f> after = vertices_of(changed, true);
  ASSERT_GT(before.size(), 1000u);
  EXPECT_NEAR(static_cast<double>(after.size()) / static_cast<double>(before.size()), 1.0, 0.25);
  std::set<std::array<int, 3>> cells_before;
  for (const Eigen::Vector3f& v : before)
    cells_before.insert({static_cast<int>(std::floor(v.x() / 0.5f)),
                         static_cast<int>(std::floor(v.y() / 0.5f)),
                         static_cast<int>(std::floor(v.z() / 0.5f))});
  size_t same_cell = 0;
  for (const Eigen::Vector3f& v : after)
    same_cell += cells_before.count({static_cast<int>(std::floor(v.x() / 0.5f)),
                                     static_cast<int>(std::floor(v.y() / 0.5f)),
                                     static_cast<int>(std::floor(v.z() / 0.5f))});
  // Cars of the same bay overlap in part: most of another day's car is elsewhere.
  EXPECT_LT(static_cast<double>(same_cell) / static_cast<double>(after.size()), 0.6);
}

TEST(SimSceneLibrary, NamedPathsStayInsideAndClearOfObstacles) {
  for (const std::string& scene : scene_names()) {
    const mesh::TriangleMesh mesh = build_scene(scene);
    const RayCaster caster(mesh);
    for (const std::string& name : path_names(scene)) {
      const NamedPath path = scene_path(scene, name);
      const auto trajectory = make_spline_trajectory(path.waypoints_m, path.speed_mps, path.tilt);
      EXPECT_GT(trajectory->duration_s(), 5.0) << scene << " " << name;
      EXPECT_NO_THROW(check_trajectory_inside(*trajectory, mesh, trajectory->duration_s()))
          << scene << " " << name;
      // No surface within 25 cm of the sensor, horizontally, anywhere along the path.
      for (double t = 0.0; t < trajectory->duration_s(); t += 0.05) {
        const Eigen::Vector3f p = trajectory->pose(t).translation().cast<float>();
        for (int k = 0; k < 16; ++k) {
          Ray ray;
          ray.origin = p;
          ray.direction = Eigen::Vector3f(std::cos(k * M_PI / 8), std::sin(k * M_PI / 8), 0);
          ray.max_distance_m = 0.25f;
          ASSERT_FALSE(caster.intersect(ray).hit())
              << scene << " " << name << " touches something at t = " << t;
        }
      }
    }
  }
  EXPECT_THROW(scene_path("lab", "fly"), std::invalid_argument);
  EXPECT_THROW(build_scene("moon"), std::invalid_argument);
}

}  // namespace
}  // namespace featsense::slam
