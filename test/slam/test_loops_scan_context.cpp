#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

#include "common/test_poses.hpp"
#include "featsense/slam/loops/scan_context.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "scene_sampling.hpp"

namespace featsense::slam::loops {
namespace {

using test::pose;

/// What a sensor at `T_map_sensor` has around it in the parking scene, in its levelled frame:
/// a noisy sampling of the surfaces within 50 m (no occlusion: the descriptor's bins keep the
/// highest point anyway).
ScanContext descriptor_at(const mesh::TriangleMesh& scene, const Eigen::Isometry3d& T_map_sensor,
                          uint32_t seed) {
  const Eigen::Vector3f centre = T_map_sensor.translation().cast<float>();
  std::vector<Eigen::Vector3f> points =
      test::sample_scene(scene, centre, 50.0f, 40000, 0.02f, seed);
  const Eigen::Isometry3d T_sensor_map = T_map_sensor.inverse();
  const Eigen::Matrix3d L = levelling(T_map_sensor);
  for (Eigen::Vector3f& p : points) p = (L * (T_sensor_map * p.cast<double>())).cast<float>();
  return make_scan_context(points);
}

double wrapped_deg(double radians) {
  double d = std::remainder(radians, 2.0 * M_PI) * 180.0 / M_PI;
  return d;
}

TEST(ScanContext, FindsARevisitTurnedHalfWayRound) {
  const mesh::TriangleMesh scene = build_scene("parking");
  const Eigen::Isometry3d first = pose(0.1, 0.0, 0.0, {30.0, 10.8, 1.9});
  // Back along the same lane the other way, 0.6 m to the side.
  const Eigen::Isometry3d revisit = pose(0.1 + M_PI, 0.0, 0.0, {30.3, 11.4, 1.9});
  const Eigen::Isometry3d elsewhere = pose(0.1, 0.0, 0.0, {8.0, 26.0, 1.9});
  const ScanContext a = descriptor_at(scene, first, 1);
  const ScanContext b = descriptor_at(scene, revisit, 2);
  const ScanContext c = descriptor_at(scene, elsewhere, 3);
  const ScanContextMatch same = match(b, a);
  const ScanContextMatch other = match(b, c);
  EXPECT_LT(same.distance, 0.25);
  EXPECT_LT(same.distance, 0.6 * other.distance);
  // The revisit's heading is the first one's plus 180 degrees: within a sector (6 degrees).
  EXPECT_LT(std::abs(wrapped_deg(same.yaw_rad - M_PI)), 6.5) << same.yaw_rad * 180.0 / M_PI;
  EXPECT_LT(ring_key_distance(a, b), ring_key_distance(c, b));
}

TEST(ScanContext, YawOfAnyTurnAndTiltedSensorsAgree) {
  const mesh::TriangleMesh scene = build_scene("parking");
  const Eigen::Isometry3d first = pose(0.0, 0.0, 0.0, {45.0, 11.0, 3.0});
  const ScanContext a = descriptor_at(scene, first, 4);
  for (double yaw_deg : {-120.0, -45.0, 30.0, 90.0}) {
    // A multirotor's tilt changes nothing once levelled.
    const Eigen::Isometry3d turned = pose(yaw_deg * M_PI / 180.0, 0.12, -0.08, {45.0, 11.0, 3.0});
    const ScanContextMatch m = match(descriptor_at(scene, turned, 5), a);
    EXPECT_LT(m.distance, 0.2) << yaw_deg;
    EXPECT_LT(std::abs(wrapped_deg(m.yaw_rad) - yaw_deg), 6.5) << yaw_deg;
  }
}

TEST(ScanContext, LevellingKeepsTheHeadingAndRemovesTilt) {
  const Eigen::Isometry3d T = pose(0.7, 0.2, -0.1, {1.0, 2.0, 3.0});
  const Eigen::Matrix3d L = levelling(T);
  // The sensor's x axis, levelled, points forward in the horizontal plane.
  const Eigen::Vector3d forward = L * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::atan2(forward.y(), forward.x()), 0.0, 1e-9);
  // Up in the levelled frame is up in the map.
  const Eigen::Vector3d up_in_sensor = T.rotation().transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_LT((L * up_in_sensor - Eigen::Vector3d::UnitZ()).norm(), 1e-9);
}

TEST(ScanContext, EmptyAndMismatchedDescriptors) {
  const ScanContext empty = make_scan_context({});
  EXPECT_EQ(empty.rings, 20);
  EXPECT_EQ(match(empty, empty).distance, 1.0);  // nothing to compare: nothing alike
  ScanContextSettings small;
  small.rings = 10;
  EXPECT_THROW(match(make_scan_context({}, small), empty), std::invalid_argument);
  small.rings = 0;
  EXPECT_THROW(make_scan_context({}, small), std::invalid_argument);
  // Non-finite points are skipped, not binned.
  const ScanContext one =
      make_scan_context({Eigen::Vector3f(5.0f, 0.0f, 1.0f), Eigen::Vector3f(NAN, 0.0f, 0.0f)});
  float total = 0.0f;
  for (float v : one.bins) total += v > 0.0f ? 1.0f : 0.0f;
  EXPECT_EQ(total, 1.0f);
}

}  // namespace
}  // namespace featsense::slam::loops
