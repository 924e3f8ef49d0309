// The built-in scenes: deterministic, their named paths inside them and clear of obstacles,
// foliage made of many small facets.

#include <gtest/gtest.h>

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
