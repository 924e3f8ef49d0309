#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <vector>

#include "common/test_poses.hpp"
#include "featsense/slam/refine/vgicp.hpp"
#include "featsense/slam/refine/weak_directions.hpp"

namespace featsense::slam::refine {
namespace {

using test::pose;

Vector6d unit(int k) { return Vector6d::Unit(k); }

/// J^T J of point-to-plane rows [(p x n)^T, n^T]: what a registration against these planes'
/// points knows of the pose, in the tangent [rotation, translation].
Matrix6d plane_information(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& rows) {
  Matrix6d h = Matrix6d::Zero();
  for (const auto& [p, n] : rows) {
    Vector6d j;
    j.head<3>() = p.cross(n);
    j.tail<3>() = n;
    h += j * j.transpose();
  }
  return h;
}

/// A floor (z = 0) and one wall (x = 5) over 20 m along y: nothing holds the shift along y.
std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> floor_and_wall() {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rows;
  for (int i = -10; i <= 10; ++i) {
    for (int j = -10; j <= 10; ++j)
      rows.push_back({{0.5 * i, 1.0 * j, 0.0}, Eigen::Vector3d::UnitZ()});
    for (int k = 0; k < 3; ++k) rows.push_back({{5.0, 1.0 * i, 0.5 + k}, Eigen::Vector3d::UnitX()});
  }
  return rows;
}

TEST(WeakDirections, AFloorAndOneWallLeaveTheShiftAlongTheWall) {
  const WeakDirections weak = weak_directions(plane_information(floor_and_wall()), 5.0, 0.01);
  EXPECT_EQ(weak.count, 1);
  EXPECT_LT(weak.weakest_ratio, 1e-9);
  // A shift along y is dropped, one across the wall or up is kept as it is.
  EXPECT_LT((weak.keep_strong * unit(4)).norm(), 1e-9);
  EXPECT_LT((weak.keep_strong * unit(3) - unit(3)).norm(), 1e-9);
  EXPECT_LT((weak.keep_strong * unit(5) - unit(5)).norm(), 1e-9);
  // A turn about the vertical moves the wall: kept.
  EXPECT_LT((weak.keep_strong * unit(2) - unit(2)).norm(), 1e-9);
}

TEST(WeakDirections, ARoomHoldsEveryDirection) {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> rows = floor_and_wall();
  for (int i = -5; i <= 5; ++i)
    for (int k = 0; k < 3; ++k) rows.push_back({{0.5 * i, 8.0, 0.5 + k}, Eigen::Vector3d::UnitY()});
  const WeakDirections weak = weak_directions(plane_information(rows), 5.0, 0.01);
  EXPECT_EQ(weak.count, 0);
  EXPECT_TRUE(weak.keep_strong.isIdentity(1e-12));
  EXPECT_GT(weak.weakest_ratio, 0.01);
}

TEST(WeakDirections, OffOrUnknown) {
  EXPECT_EQ(weak_directions(plane_information(floor_and_wall()), 5.0, 0.0).count, 0);
  Matrix6d bad = Matrix6d::Identity();
  bad(2, 2) = std::nan("");
  const WeakDirections none = weak_directions(bad, 5.0, 0.01);
  EXPECT_EQ(none.count, 6);
  EXPECT_TRUE(none.keep_strong.isZero());
  EXPECT_EQ(weak_directions(Matrix6d::Zero(), 5.0, 0.01).count, 6);
}

/// Points of a straight corridor 2.5 m wide and 3 m high, `half_length` along y each way,
/// floor and walls, with 1 cm noise: nothing along it tells one place from another. With
/// `ends`, walls close it at both ends: a room.
std::vector<Eigen::Vector3f> corridor(int count, uint32_t seed, float half_length = 15.0f,
                                      bool ends = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> along(-half_length, half_length), across(-1.25f, 1.25f),
      up(0.0f, 3.0f);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < count; ++i) {
    const float y = along(rng);
    if (ends && i % 4 == 3) {
      points.push_back(
          {across(rng), (i % 8 == 3 ? half_length : -half_length) + noise(rng), up(rng)});
      continue;
    }
    switch (i % 3) {
      case 0:
        points.push_back({across(rng), y, noise(rng)});
        break;
      case 1:
        points.push_back({-1.25f + noise(rng), y, up(rng)});
        break;
      default:
        points.push_back({1.25f + noise(rng), y, up(rng)});
    }
  }
  return points;
}

TEST(AlignShared, KeepsTheGuessAlongACorridorAndCorrectsAcrossIt) {
  VgicpSettings settings;
  settings.voxel_sizes_m = {1.0, 0.5};
  const VgicpTarget target(with_covariances(corridor(30000, 1), 10), settings);
  const GaussianCloud scan = with_covariances(corridor(10000, 2), 10);
  // The guess is 4 cm off across the corridor and 10 cm along it; the truth is the identity.
  const Eigen::Isometry3d guess = pose(0.0, 0.0, 0.0, {0.04, 0.10, 0.0});
  const std::vector<SharedSource> sources = {{&scan, guess, 1.0}};

  settings.min_constraint_ratio = 0.01;
  const SharedVgicpResult held = align_shared(target, sources, settings);
  ASSERT_TRUE(held.converged);
  EXPECT_GE(held.weak_directions, 1);
  const Eigen::Isometry3d& result = held.poses.front();
  EXPECT_NEAR(result.translation().x(), 0.0, 0.005);  // corrected across
  EXPECT_NEAR(result.translation().y(), 0.10, 1e-3);  // kept along
  EXPECT_NEAR(result.translation().z(), 0.0, 0.005);

  // A room: every direction constrained, nothing held, the same result as without the rule.
  const VgicpTarget room_target(with_covariances(corridor(30000, 3, 3.0f, true), 10), settings);
  const GaussianCloud room_cloud = with_covariances(corridor(10000, 4, 3.0f, true), 10);
  const std::vector<SharedSource> room_sources = {{&room_cloud, guess, 1.0}};
  const SharedVgicpResult with_rule = align_shared(room_target, room_sources, settings);
  settings.min_constraint_ratio = 0.0;
  const SharedVgicpResult without = align_shared(room_target, room_sources, settings);
  EXPECT_EQ(with_rule.weak_directions, 0);
  EXPECT_GT(with_rule.weakest_ratio, 0.01);
  EXPECT_TRUE(with_rule.poses.front().isApprox(without.poses.front(), 1e-12));
  EXPECT_EQ(without.weak_directions, 0);
}

}  // namespace
}  // namespace featsense::slam::refine
