// Navigation layers on analytic meshes: a ramp, a step and a flat floor.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "featsense/mesh/navigation_layers.hpp"
#include "mesh/mesh_test_shapes.hpp"

namespace featsense::mesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A 4 m x 4 m grid of 0.1 m cells; z = height(x).
template <typename Height>
TriangleMesh terrain(Height height) {
  TriangleMesh m = test::grid_plane(-2.0f, 2.0f, -2.0f, 2.0f, 0.0f, 40);
  for (Eigen::Vector3f& v : m.vertices) v.z() = height(v.x());
  return m;
}

TEST(NavigationLayers, FlatFloorIsFreeAndSmooth) {
  const NavigationLayers layers = compute_navigation_layers(terrain([](float) { return 1.5f; }));
  for (size_t i = 0; i < layers.cost.size(); ++i) {
    EXPECT_NEAR(layers.inclination_deg[i], 0.0, 1e-3);
    EXPECT_NEAR(layers.roughness_deg[i], 0.0, 1e-3);
    EXPECT_EQ(layers.height_diff_m[i], 0.0f);
    EXPECT_EQ(layers.cost[i], 0.0f);
  }
  for (const uint8_t lethal : layers.lethal_faces) EXPECT_EQ(lethal, 0);
}

TEST(NavigationLayers, RampGivesItsSlope) {
  for (const double slope_deg : {5.0, 15.0, 30.0}) {
    const float gradient = static_cast<float>(std::tan(slope_deg * kPi / 180.0));
    const TriangleMesh ramp = terrain([gradient](float x) { return gradient * x; });
    NavigationSettings settings;
    settings.max_step_m = 10.0;  // only the slope limit applies here
    const NavigationLayers layers = compute_navigation_layers(ramp, settings);
    for (size_t i = 0; i < layers.cost.size(); ++i) {
      // float coordinates of up to 2 m: the normal is exact to ~1e-5 rad.
      ASSERT_NEAR(layers.inclination_deg[i], slope_deg, 2e-3);
      ASSERT_NEAR(layers.roughness_deg[i], 0.0, 2e-3);
      const double expected_cost = slope_deg >= 20.0 ? 1.0 : slope_deg / 20.0;
      ASSERT_NEAR(layers.cost[i], expected_cost, 1e-4);
    }
    for (const uint8_t lethal : layers.lethal_faces) EXPECT_EQ(lethal, slope_deg >= 20.0 ? 1 : 0);
  }
}

TEST(NavigationLayers, StepGivesItsHeight) {
  const float step_m = 0.25f;
  const TriangleMesh step = terrain([step_m](float x) { return x > -0.05f ? step_m : 0.0f; });
  const NavigationLayers layers = compute_navigation_layers(step);
  for (size_t i = 0; i < step.vertices.size(); ++i) {
    const float x = step.vertices[i].x();
    // The radius is a 3D distance: across the 0.25 m step, a vertex sees the other side when
    // dx^2 + 0.25^2 < 0.3^2, dx < 0.166 m, so only the columns x = -0.1 and x = 0 at the edge;
    // from 0.2 m on, flat ground.
    if (x > -0.15f && x < 0.05f) {
      EXPECT_NEAR(layers.height_diff_m[i], step_m, 1e-6) << "x " << x;
      EXPECT_EQ(layers.cost[i], 1.0f);
    } else if (x < -0.25f || x > 0.15f) {
      EXPECT_EQ(layers.height_diff_m[i], 0.0f) << "x " << x;
      EXPECT_EQ(layers.cost[i], 0.0f);
    }
  }
}

TEST(NavigationLayers, FaceNormalsAreAreaWeighted) {
  // One big face tilted 45 deg about y and one tiny flat face share vertex 0: the big one wins.
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 1}, {0, 1, 0}, {-0.01f, 0, 0}, {0, -0.01f, 0}};
  m.triangles = {{0, 1, 2}, {0, 3, 4}};
  const std::vector<Eigen::Vector3f> normals = vertex_normals(m);
  const Eigen::Vector3f big = Eigen::Vector3f(-1, 0, 1).normalized();
  const Eigen::Vector3f small = Eigen::Vector3f::UnitZ();
  // Face areas: sqrt(2)/2 and 5e-5; the weighted mean direction by hand.
  const Eigen::Vector3f expected = (big * std::sqrt(2.0f) / 2 + small * 5e-5f).normalized();
  EXPECT_LT((normals[0] - expected).norm(), 1e-6f);
}

TEST(NavigationLayers, BadInputIsRejected) {
  EXPECT_THROW(compute_navigation_layers(TriangleMesh{}), MeshError);
  TriangleMesh with_nan = terrain([](float) { return 0.0f; });
  with_nan.vertices[3].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(compute_navigation_layers(with_nan), MeshError);
  NavigationSettings zero_radius;
  zero_radius.radius_m = 0.0;
  EXPECT_THROW(compute_navigation_layers(terrain([](float) { return 0.0f; }), zero_radius),
               MeshError);
}

}  // namespace
}  // namespace featsense::mesh
