#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

#include "common/test_poses.hpp"
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "scene_sampling.hpp"

namespace featsense::slam::loops {
namespace {

using test::pose;

/// East along the parking lot's middle lane, a U-turn, and back west 1.5 m further north: the
/// way back revisits the way out in the opposite direction. A keyframe every 2 m; the odometry
/// drifts 0.03 deg of yaw and 1 cm sideways per metre.
struct OutAndBack {
  std::vector<Eigen::Isometry3d> truth;
  std::vector<Eigen::Isometry3d> odometry;
  std::vector<double> travelled_m;
  std::vector<int64_t> stamps_ns;

  OutAndBack() {
    const double step = 2.0;
    for (double x = 6.0; x <= 58.0; x += step) truth.push_back(pose(0.0, 0.0, 0.0, {x, 10.5, 1.9}));
    for (double a = 0.25; a < 1.0; a += 0.25)  // the U-turn
      truth.push_back(
          pose(a * M_PI, 0.0, 0.0,
               {58.0 + 0.75 * std::sin(a * M_PI), 11.25 - 0.75 * std::cos(a * M_PI), 1.9}));
    for (double x = 58.0; x >= 6.0; x -= step)
      truth.push_back(pose(M_PI, 0.0, 0.0, {x, 12.0, 1.9}));
    odometry.push_back(truth.front());
    travelled_m.push_back(0.0);
    stamps_ns.push_back(0);
    for (size_t i = 1; i < truth.size(); ++i) {
      const Eigen::Isometry3d motion = truth[i - 1].inverse() * truth[i];
      const double d = motion.translation().norm();
      const Eigen::Isometry3d drift = pose(0.03 * M_PI / 180.0 * d, 0.0, 0.0, {0.0, 0.01 * d, 0.0});
      odometry.push_back(odometry.back() * motion * drift);
      travelled_m.push_back(travelled_m.back() + d);
      stamps_ns.push_back(stamps_ns.back() + static_cast<int64_t>(d / 5.0 * 1e9));  // 5 m/s
    }
  }
};

double rmse(const std::vector<Eigen::Isometry3d>& a, const std::vector<Eigen::Isometry3d>& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.size(); ++i)
    sum += (a[i].translation() - b[i].translation()).squaredNorm();
  return std::sqrt(sum / static_cast<double>(a.size()));
}

/// How far apart `poses` put the way out and the way back where they pass the same place
/// (keyframe i out and the one back at its x), against the truth: a map drawn with them
/// shows each wall doubled by this much.
double revisit_error(const OutAndBack& path, const std::vector<Eigen::Isometry3d>& poses) {
  double sum = 0.0;
  int pairs = 0;
  for (size_t i = 0; i < path.truth.size(); ++i) {
    for (size_t j = i + 1; j < path.truth.size(); ++j) {
      const Eigen::Vector3d d = path.truth[j].translation() - path.truth[i].translation();
      if (std::abs(d.x()) > 0.5 || j - i < 10) continue;
      const Eigen::Isometry3d truth = path.truth[i].inverse() * path.truth[j];
      const Eigen::Isometry3d estimate = poses[i].inverse() * poses[j];
      sum += (truth.translation() - estimate.translation()).norm();
      ++pairs;
    }
  }
  return pairs ? sum / pairs : 0.0;
}

/// A loop's measured pose (after the graph) against the truth: a wrong one bends the map.
void expect_true_loops(const LoopCloser& closer, const OutAndBack& path) {
  for (const LoopRecord& loop : closer.loops()) {
    const Eigen::Isometry3d truth = path.truth[loop.candidate].inverse() * path.truth[loop.query];
    const Eigen::Isometry3d measured =
        closer.graph().pose(loop.candidate).inverse() * closer.graph().pose(loop.query);
    EXPECT_LT((truth.translation() - measured.translation()).norm(), 0.15)
        << loop.candidate << " - " << loop.query;
    EXPECT_LT(test::angle_between(truth, measured) * 180.0 / M_PI, 1.0);
  }
}

TEST(LoopCloser, ClosesLoopsDrivenTheOtherWayAndCorrectsTheDrift) {
  const mesh::TriangleMesh scene = build_scene("parking");
  const OutAndBack path;
  const LoopSettings settings;
  LoopCloser closer(settings);
  for (size_t i = 0; i < path.truth.size(); ++i) {
    closer.add_keyframe(path.stamps_ns[i], path.travelled_m[i], path.odometry[i],
                        test::keyframe_scan_at(scene, path.truth[i], static_cast<uint32_t>(i)));
  }
  closer.optimise();
  ASSERT_EQ(closer.keyframes(), path.truth.size());
  std::string rejected;
  for (const auto& [reason, count] : closer.counts().rejected)
    rejected += reason + ": " + std::to_string(count) + "; ";
  EXPECT_GE(closer.loops().size(), 3u) << closer.counts().candidates << " candidates, "
                                       << closer.counts().verified << " verified; " << rejected;
  for (const LoopRecord& loop : closer.loops()) {
    // Every loop joins places near each other (the lanes are 1.5 m apart, keyframes 2 m).
    EXPECT_LT(
        (path.truth[loop.query].translation() - path.truth[loop.candidate].translation()).norm(),
        6.0);
    EXPECT_LE(loop.fitness_m, settings.max_fitness_m);
  }
  expect_true_loops(closer, path);
  // The way back lies on the way out again (the doubled walls are gone), and the path as a
  // whole is nearer the truth: the drift of the way out is spread over the round trip, not
  // undone (nothing but the odometry says where the way out went).
  const double doubled_before = revisit_error(path, path.odometry);
  const double doubled_after = revisit_error(path, closer.graph().poses());
  EXPECT_GT(doubled_before, 0.5);
  EXPECT_LT(doubled_after, 0.1) << "odometry " << doubled_before;
  EXPECT_LT(rmse(closer.graph().poses(), path.truth), 0.6 * rmse(path.odometry, path.truth));
  // The correction between keyframes reproduces the keyframes' own poses.
  const TrajectoryCorrection correction = closer.correction();
  for (size_t i = 0; i < path.truth.size(); i += 7) {
    EXPECT_TRUE(correction.apply(path.travelled_m[i], path.odometry[i])
                    .isApprox(closer.graph().pose(i), 1e-6));
  }
  EXPECT_GT(closer.counts().cloud_bytes, 0u);
  // At the end of a run the records take the clouds over: the same records, one copy.
  const std::vector<KeyframeRecord> copied = closer.keyframe_records();
  const std::vector<KeyframeRecord> released = closer.release_keyframe_records();
  ASSERT_EQ(released.size(), copied.size());
  size_t bytes = 0;
  for (size_t i = 0; i < copied.size(); ++i) {
    EXPECT_EQ(released[i].stamp_ns, copied[i].stamp_ns);
    EXPECT_TRUE(released[i].T_map_sensor.isApprox(copied[i].T_map_sensor, 0.0));
    EXPECT_EQ(released[i].cloud.coordinates(), copied[i].cloud.coordinates());
    bytes += released[i].cloud.bytes();
  }
  EXPECT_EQ(bytes, closer.counts().cloud_bytes);
  for (const KeyframeRecord& left : closer.keyframe_records()) EXPECT_EQ(left.cloud.size(), 0u);
}

TEST(LoopCloser, OnlyTrueLoopsWhereTheLaneLooksAlikeEverywhere) {
  const mesh::TriangleMesh scene = build_scene("parking");
  const OutAndBack path;
  // Places only 10 m and 2 s back may be candidates: the lane's rows of cars look alike
  // every few metres. A loop to a place 10 m back is no revisit, but harmless where its pose
  // is right; one that mistakes a car for the next would bend the map.
  LoopSettings settings;
  settings.min_separation_m = 10.0;
  settings.min_separation_s = 2.0;
  LoopCloser closer(settings);
  // The way out alone.
  for (size_t i = 0; i < 27; ++i) {
    closer.add_keyframe(path.stamps_ns[i], path.travelled_m[i], path.odometry[i],
                        test::keyframe_scan_at(scene, path.truth[i], static_cast<uint32_t>(i)));
  }
  EXPECT_GT(closer.counts().candidates, 0u);
  expect_true_loops(closer, path);
}

TEST(KeyframeSelector, EveryDistanceOrTurn) {
  KeyframeSelector selector(1.0, 15.0);
  EXPECT_TRUE(selector.next(pose(0.0, 0.0, 0.0, {0, 0, 0})));
  EXPECT_FALSE(selector.next(pose(0.0, 0.0, 0.0, {0.6, 0, 0})));
  EXPECT_TRUE(selector.next(pose(0.0, 0.0, 0.0, {1.2, 0, 0})));
  EXPECT_NEAR(selector.travelled_m(), 1.2, 1e-12);
  EXPECT_FALSE(selector.next(pose(0.2, 0.0, 0.0, {1.3, 0, 0})));  // 11 degrees
  EXPECT_TRUE(selector.next(pose(0.3, 0.0, 0.0, {1.3, 0, 0})));   // 17 degrees, standing
}

}  // namespace
}  // namespace featsense::slam::loops
