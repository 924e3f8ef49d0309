#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <vector>

#include "featsense/slam/loops/map_layout.hpp"
#include "featsense/slam/loops/relocalizer.hpp"
#include "featsense/slam/loops/scan_context.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::slam::loops {
namespace {

Eigen::Isometry3d pose(double yaw_deg, double roll_deg, const Eigen::Vector3d& at) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(roll_deg * M_PI / 180.0, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = at;
  return T;
}

/// A district of buildings of irregular sizes and turns, and posts, on flat ground: the outer
/// walls sampled every 0.4 m, the ground every metre. `copies` districts side by side, 120 m
/// apart along x, all alike (twin blocks).
std::vector<Eigen::Vector3f> district(int copies = 1) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> across(-60.0, 60.0);
  std::uniform_real_distribution<double> size(3.0, 12.0);
  std::uniform_real_distribution<double> tall(3.0, 8.0);
  std::uniform_real_distribution<double> turn(0.0, M_PI);
  std::vector<Eigen::Vector3f> one;
  for (int b = 0; b < 30; ++b) {
    const Eigen::Vector2d centre(across(rng), across(rng));
    const double a = size(rng), c = size(rng), h = tall(rng);
    const Eigen::Rotation2Dd R(turn(rng));
    const Eigen::Vector2d corners[] = {
        {-a / 2, -c / 2}, {a / 2, -c / 2}, {a / 2, c / 2}, {-a / 2, c / 2}};
    for (int e = 0; e < 4; ++e) {
      const Eigen::Vector2d p = corners[e], q = corners[(e + 1) % 4];
      const int steps = static_cast<int>((q - p).norm() / 0.4);
      for (int s = 0; s <= steps; ++s) {
        const Eigen::Vector2d w = centre + R * (p + (q - p) * s / std::max(steps, 1));
        for (double z = 0.2; z <= h; z += 0.4) one.emplace_back(w.x(), w.y(), z);
      }
    }
  }
  for (int k = 0; k < 40; ++k) {
    const Eigen::Vector2d w(across(rng), across(rng));
    for (double z = 0.2; z <= 3.0; z += 0.4) one.emplace_back(w.x(), w.y(), z);
  }
  for (double x = -70.0; x <= 70.0; x += 1.0)
    for (double y = -70.0; y <= 70.0; y += 1.0) one.emplace_back(x, y, 0.0);
  std::vector<Eigen::Vector3f> all;
  for (int k = 0; k < copies; ++k)
    for (const Eigen::Vector3f& p : one) all.emplace_back(p.x() + 120.0f * k, p.y(), p.z());
  return all;
}

/// The world's points within `range` of the sensor at `T`, in its frame, every `every`-th.
std::vector<Eigen::Vector3f> seen_from(const std::vector<Eigen::Vector3f>& world,
                                       const Eigen::Isometry3d& T, double range, int every = 1) {
  const Eigen::Isometry3f inverse = T.inverse().cast<float>();
  std::vector<Eigen::Vector3f> out;
  int k = 0;
  for (const Eigen::Vector3f& p : world) {
    if ((p.head<2>() - T.translation().head<2>().cast<float>()).norm() > range) continue;
    if (k++ % every == 0) out.push_back(inverse * p);
  }
  return out;
}

/// Keyframes every 10 m along y = -40 from x = -60 to 60 + 120 (copies - 1), their clouds
/// what they see within 60 m.
std::vector<MapKeyframe> keyframes_along(const std::vector<Eigen::Vector3f>& world,
                                         int copies = 1) {
  std::vector<MapKeyframe> keyframes;
  for (double x = -60.0; x <= 60.0 + 120.0 * (copies - 1); x += 10.0) {
    MapKeyframe keyframe;
    keyframe.index = static_cast<uint32_t>(keyframes.size());
    keyframe.T_map_sensor = pose(0.0, 0.0, {x, -40.0, 1.8});
    const std::vector<Eigen::Vector3f> points = seen_from(world, keyframe.T_map_sensor, 60.0);
    keyframe.descriptor = make_scan_context(points);
    keyframe.cloud = CompactCloud(points);
    keyframes.push_back(std::move(keyframe));
  }
  return keyframes;
}

double heading_error_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return rotation_angle_deg(a.linear().transpose() * b.linear());
}

TEST(MapLayout, FindsAScanFarFromEveryKeyframeAtAnyHeading) {
  const std::vector<Eigen::Vector3f> world = district();
  const std::vector<MapKeyframe> keyframes = keyframes_along(world);
  const MapLayout layout(keyframes);
  EXPECT_GT(layout.counts().upright_cells, 500u);
  // 50 m from the nearest keyframe, turned 137 degrees and tilted 3 degrees; every other
  // point of what it sees.
  const Eigen::Isometry3d truth = pose(137.0, 3.0, {20.0, 10.0, 1.2});
  const std::vector<LayoutPeak> peaks =
      layout.search(seen_from(world, truth, 40.0, 2), levelling(truth));
  ASSERT_FALSE(peaks.empty());
  EXPECT_LT((peaks[0].T_map_query.translation() - truth.translation()).head<2>().norm(), 1.5);
  EXPECT_LT(heading_error_deg(peaks[0].T_map_query, truth), 2.5);
  EXPECT_GT(peaks[0].score, 0.5);
  for (size_t i = 1; i < peaks.size(); ++i) EXPECT_LE(peaks[i].score, peaks[i - 1].score);
}

TEST(MapLayout, TheBoundedSearchFindsWhatTryingEveryPlaceFinds) {
  const std::vector<Eigen::Vector3f> world = district();
  const std::vector<MapKeyframe> keyframes = keyframes_along(world);
  MapLayoutSettings settings;
  settings.scan_range_m = 20.0;  // fewer headings: the exhaustive search stays short
  settings.min_score = 0.0;
  MapLayoutSettings every = settings;
  every.exhaustive = true;
  const MapLayout bounded(keyframes, settings);
  const MapLayout exhaustive(keyframes, every);
  for (const Eigen::Isometry3d& truth :
       {pose(-40.0, 0.0, {-25.0, 5.0, 1.8}), pose(75.0, 0.0, {30.0, -20.0, 1.8})}) {
    const std::vector<Eigen::Vector3f> points = seen_from(world, truth, 20.0);
    const std::vector<LayoutPeak> a = bounded.search(points, levelling(truth));
    const std::vector<LayoutPeak> b = exhaustive.search(points, levelling(truth));
    ASSERT_FALSE(a.empty());
    ASSERT_FALSE(b.empty());
    EXPECT_DOUBLE_EQ(a[0].score, b[0].score);
    EXPECT_LT((a[0].T_map_query.translation() - b[0].T_map_query.translation()).norm(), 1e-9);
    EXPECT_LT(heading_error_deg(a[0].T_map_query, b[0].T_map_query), 1e-6);
  }
}

TEST(MapLayout, TwinBlocksAreBothProposed) {
  const std::vector<Eigen::Vector3f> world = district(2);
  const std::vector<MapKeyframe> keyframes = keyframes_along(world, 2);
  const MapLayout layout(keyframes);
  const Eigen::Isometry3d truth = pose(20.0, 0.0, {-10.0, 0.0, 1.8});
  const std::vector<LayoutPeak> peaks =
      layout.search(seen_from(world, truth, 40.0), levelling(truth));
  ASSERT_GE(peaks.size(), 2u);
  // The same place in each district, 120 m apart, fitting alike.
  bool here = false, twin = false;
  for (size_t i = 0; i < 2; ++i) {
    const Eigen::Vector2d at = peaks[i].T_map_query.translation().head<2>();
    here = here || (at - Eigen::Vector2d(-10.0, 0.0)).norm() < 1.5;
    twin = twin || (at - Eigen::Vector2d(110.0, 0.0)).norm() < 1.5;
  }
  EXPECT_TRUE(here);
  EXPECT_TRUE(twin);
  EXPECT_NEAR(peaks[0].score, peaks[1].score, 0.05);
}

TEST(MapLayout, AScanOfGroundAloneProposesNothing) {
  const std::vector<Eigen::Vector3f> world = district();
  const std::vector<MapKeyframe> keyframes = keyframes_along(world);
  const MapLayout layout(keyframes);
  std::vector<Eigen::Vector3f> ground;
  for (double x = -30.0; x <= 30.0; x += 0.5)
    for (double y = -30.0; y <= 30.0; y += 0.5) ground.emplace_back(x, y, -1.8);
  EXPECT_TRUE(layout.search(ground, Eigen::Matrix3d::Identity()).empty());
}

TEST(MapLayout, AnEmptyMapProposesNothing) {
  const MapLayout layout({});
  EXPECT_EQ(layout.counts().upright_cells, 0u);
  const std::vector<Eigen::Vector3f> world = district();
  EXPECT_TRUE(
      layout
          .search(seen_from(world, pose(0.0, 0.0, {0, 0, 1.8}), 40.0), Eigen::Matrix3d::Identity())
          .empty());
}

TEST(MapLayout, AMapTooWideForItsCellsIsSearchedByNothing) {
  // Two keyframes 20,000 km apart: a grid of metre cells between them would not fit anywhere.
  const std::vector<Eigen::Vector3f> world = district();
  std::vector<MapKeyframe> keyframes = keyframes_along(world);
  keyframes.resize(2);
  keyframes[1].T_map_sensor.translation().x() = 2e7;
  const MapLayout layout(keyframes);
  EXPECT_TRUE(layout.counts().too_large);
  const Eigen::Isometry3d at = pose(0.0, 0.0, {0, 0, 1.8});
  EXPECT_TRUE(layout.search(seen_from(world, at, 40.0), levelling(at)).empty());
}

/// A recording 50 m from the map's path, whose descriptors' places (the map's keyframes)
/// never hold, placed by the layout's, or by nothing without a layout. The verifier is an
/// oracle: a place within 3 m and 5 degrees of the truth is the truth, any other is refused.
std::optional<Relocalization> place_far_recording(bool with_layout) {
  const std::vector<Eigen::Vector3f> world = district();
  std::vector<MapKeyframe> keyframes = keyframes_along(world);
  travelled_from_positions(keyframes);
  Eigen::Isometry3d truth;
  const PlaceVerifier oracle = [&](const Eigen::Isometry3d& guess, const refine::GaussianCloud&) {
    PlaceCheck check;
    if ((guess.translation() - truth.translation()).head<2>().norm() < 3.0 &&
        heading_error_deg(guess, truth) < 5.0) {
      check.T_map_query = truth;
      check.inlier_fraction = 0.8;
    } else {
      check.rejection = "surface: inliers";
    }
    return check;
  };
  MapLayoutSettings settings;
  const auto layout = std::make_shared<const MapLayout>(keyframes, settings);
  Relocalizer relocalizer(keyframes, RelocalizeSettings{}, oracle, with_layout ? layout : nullptr);
  const Eigen::Isometry3d first = pose(137.0, 0.0, {20.0, 10.0, 1.8});
  std::optional<Relocalization> placed;
  for (int k = 0; k < 4 && !placed; ++k) {
    truth = first * pose(0.0, 0.0, {2.0 * k, 0.0, 0.0});
    placed = relocalizer.add_keyframe(k * 400'000'000, first.inverse() * truth, 2.0 * k,
                                      seen_from(world, truth, 60.0, 2));
  }
  if (placed) {
    EXPECT_LT((placed->T_map_session.translation() - first.translation()).norm(), 1e-6);
    EXPECT_LT(heading_error_deg(placed->T_map_session, first), 1e-6);
  }
  return placed;
}

TEST(MapLayout, ARelocalizerFindsWhatNoDescriptorProposesFromAbove) {
  const std::optional<Relocalization> found = place_far_recording(true);
  ASSERT_TRUE(found);
  EXPECT_EQ(found->found_by, "layout");
  EXPECT_FALSE(place_far_recording(false));
}

}  // namespace
}  // namespace featsense::slam::loops
