#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "featsense/slam/trajectory/trajectory_metrics.hpp"
#include "trajectory_test_paths.hpp"

namespace featsense::test {
namespace {

using slam::Alignment;
using slam::Trajectory;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const slam::TrajectoryError& e) {
    return e.what();
  }
  return "";
}

/// The estimate as it would come out in another map frame: T_other_map * pose.
Trajectory in_other_frame(const Trajectory& t, const Eigen::Isometry3d& T_other_map) {
  Trajectory out = t;
  for (auto& pose : out.poses) pose = T_other_map * pose;
  return out;
}

TEST(TrajectoryMetrics, AlignmentRecoversARigidTransform) {
  const Trajectory gt = helix_trajectory(200);
  const Trajectory est = in_other_frame(gt, some_transform());
  const slam::TrajectoryEvaluation e = slam::evaluate_trajectory(est, gt);
  EXPECT_EQ(e.association.size(), 200u);
  EXPECT_TRUE(e.alignment.T.isApprox(some_transform().inverse(), 1e-9));
  EXPECT_DOUBLE_EQ(e.alignment.scale, 1.0);
  EXPECT_LT(e.ape.max, 1e-9);
  EXPECT_LT(e.rpe_translation.max, 1e-9);
  EXPECT_LT(e.rpe_rotation_deg.max, 1e-5);
}

TEST(TrajectoryMetrics, ScaleIsRecoveredOnlyWhenAsked) {
  const Trajectory gt = helix_trajectory(200);
  Trajectory est = in_other_frame(gt, some_transform());
  for (auto& pose : est.poses) pose.translation() *= 2.5;  // a monocular-like scale
  slam::TrajectoryEvaluationSettings settings;
  settings.alignment = Alignment::kSE3Scale;
  const slam::TrajectoryEvaluation scaled = slam::evaluate_trajectory(est, gt, settings);
  EXPECT_NEAR(scaled.alignment.scale, 1.0 / 2.5, 1e-12);
  EXPECT_TRUE(scaled.alignment.T.linear().isApprox(some_transform().linear().transpose(), 1e-9));
  EXPECT_LT(scaled.ape.max, 1e-9);
  settings.alignment = Alignment::kSE3;
  const slam::TrajectoryEvaluation rigid = slam::evaluate_trajectory(est, gt, settings);
  EXPECT_DOUBLE_EQ(rigid.alignment.scale, 1.0);
  EXPECT_GT(rigid.ape.rmse, 1.0);
}

TEST(TrajectoryMetrics, KnownNoiseGivesKnownApeWithoutAlignment) {
  const Trajectory gt = helix_trajectory(100);
  Trajectory est = gt;
  // Offsets of 0.1 m and 0.3 m in turn, in directions that change from pose to pose.
  for (size_t i = 0; i < est.size(); ++i) {
    const double size = i % 2 == 0 ? 0.1 : 0.3;
    const Eigen::Vector3d direction =
        Eigen::Vector3d(std::cos(1.0 * i), std::sin(1.0 * i), 0.5).normalized();
    est.poses[i].translation() += size * direction;
  }
  slam::TrajectoryEvaluationSettings settings;
  settings.alignment = Alignment::kNone;
  const slam::TrajectoryEvaluation e = slam::evaluate_trajectory(est, gt, settings);
  EXPECT_NEAR(e.ape.mean, 0.2, 1e-12);
  EXPECT_NEAR(e.ape.median, 0.2, 1e-12);  // even count: the mean of 0.1 and 0.3
  EXPECT_NEAR(e.ape.std, 0.1, 1e-12);
  EXPECT_NEAR(e.ape.rmse, std::sqrt(0.05), 1e-12);
  EXPECT_NEAR(e.ape.sse, 100 * 0.05, 1e-10);
  EXPECT_NEAR(e.ape.min, 0.1, 1e-12);
  EXPECT_NEAR(e.ape.max, 0.3, 1e-12);
  // With noise, the alignment moves by about noise / sqrt(n): it stays close to identity.
  settings.alignment = Alignment::kSE3;
  const slam::TrajectoryEvaluation aligned = slam::evaluate_trajectory(est, gt, settings);
  EXPECT_LT(aligned.alignment.T.translation().norm(), 0.1);
  EXPECT_LE(aligned.ape.rmse, e.ape.rmse + 1e-12);  // least squares: never worse
}

// A hand-computed example of evo's definitions (evo_ape / evo_rpe, translation part, delta 1
// frame). Ground truth moves 1 m along x per frame; the estimate turns a quarter left at
// frame 1 and then moves 1 m along its own x (= the map's y).
TEST(TrajectoryMetrics, HandComputedExampleMatchesEvoDefinitions) {
  Trajectory gt;
  Trajectory est;
  const Eigen::Matrix3d quarter = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).matrix();
  for (int i = 0; i < 3; ++i) {
    Eigen::Isometry3d q = Eigen::Isometry3d::Identity();
    q.translation() = Eigen::Vector3d(i, 0, 0);
    gt.push_back(i * 100'000'000, q);
  }
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  est.push_back(0, p);
  p.linear() = quarter;
  p.translation() = Eigen::Vector3d(1, 0, 0);
  est.push_back(100'000'000, p);
  p.translation() = Eigen::Vector3d(1, 1, 0);
  est.push_back(200'000'000, p);
  slam::TrajectoryEvaluationSettings settings;
  settings.alignment = Alignment::kNone;
  const slam::TrajectoryEvaluation e = slam::evaluate_trajectory(est, gt, settings);
  // APE: ||t_gt - t_est|| = 0, 0, sqrt(2).
  ASSERT_EQ(e.ape_m.size(), 3u);
  EXPECT_NEAR(e.ape_m[2], std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(e.ape.mean, std::sqrt(2.0) / 3, 1e-12);
  EXPECT_NEAR(e.ape.median, 0.0, 1e-12);
  EXPECT_NEAR(e.ape.rmse, std::sqrt(2.0 / 3), 1e-12);
  EXPECT_NEAR(e.ape.std, 2.0 / 3, 1e-12);  // population std: sqrt(2/3 - 2/9)
  // RPE: frame 0->1 moves 1 m along x in both, but the estimate turns 90 deg; frame 1->2 moves
  // 1 m straight ahead in both (in the sensor frame): zero error.
  EXPECT_NEAR(e.rpe_translation.max, 0.0, 1e-12);
  EXPECT_NEAR(e.rpe_rotation_deg.max, 90.0, 1e-9);
  EXPECT_NEAR(e.rpe_rotation_deg.min, 0.0, 1e-9);
  EXPECT_EQ(e.rpe_translation.count, 2u);
  EXPECT_FALSE(e.kitti.has_value());  // 2 m path: no 100 m segment
}

TEST(TrajectoryMetrics, TimeOffsetAndTolerance) {
  const Trajectory gt = helix_trajectory(100);
  Trajectory est = gt;
  for (auto& stamp : est.stamps_ns) stamp += 500'000'000;  // the estimate's clock is 0.5 s ahead
  // Without alignment: a helix shifted along itself is a screw motion, which alignment undoes.
  slam::TrajectoryEvaluationSettings settings;
  settings.alignment = Alignment::kNone;
  const slam::TrajectoryEvaluation wrong = slam::evaluate_trajectory(est, gt, settings);
  EXPECT_EQ(wrong.association.size(), 95u);  // paired with poses 5 frames later
  EXPECT_GT(wrong.ape.mean, 0.1);
  settings.association.offset_s = -0.5;
  const slam::TrajectoryEvaluation right = slam::evaluate_trajectory(est, gt, settings);
  EXPECT_EQ(right.association.size(), 100u);
  EXPECT_LT(right.ape.max, 1e-9);
  // Stamps 4 ms off pair within the default 10 ms, not within 3 ms.
  Trajectory jittered = gt;
  for (auto& stamp : jittered.stamps_ns) stamp += 4'000'000;
  EXPECT_EQ(slam::associate(jittered, gt).size(), 100u);
  EXPECT_NEAR(slam::associate(jittered, gt).max_stamp_diff_s, 0.004, 1e-9);
  slam::AssociationSettings tight;
  tight.max_diff_s = 0.003;
  EXPECT_NE(error_of([&] { slam::associate(jittered, gt, tight); }).find("no pose pair within"),
            std::string::npos);
}

TEST(TrajectoryMetrics, ShorterTrajectoryPicksPartnersAsEvo) {
  const Trajectory gt = helix_trajectory(100);  // 10 Hz
  Trajectory est;
  for (size_t i = 0; i < gt.size(); i += 5) est.push_back(gt.stamps_ns[i] + 1'000'000, gt.poses[i]);
  const slam::Association a = slam::associate(est, gt);
  ASSERT_EQ(a.size(), 20u);
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a.estimate_index[k], k);
    EXPECT_EQ(a.ground_truth_index[k], 5 * k);
  }
}

TEST(TrajectoryMetrics, BadInputGivesClearErrors) {
  const Trajectory gt = helix_trajectory(50);
  Trajectory late = gt;
  for (auto& stamp : late.stamps_ns) stamp += 3'600'000'000'000;
  EXPECT_NE(
      error_of([&] { slam::evaluate_trajectory(late, gt); }).find("time ranges do not overlap"),
      std::string::npos);
  EXPECT_NE(error_of([&] { slam::evaluate_trajectory(Trajectory{}, gt); }).find("empty"),
            std::string::npos);
  Trajectory unstamped = gt;
  unstamped.has_stamps = false;
  unstamped.poses.pop_back();
  unstamped.stamps_ns.pop_back();
  EXPECT_NE(error_of([&] { slam::evaluate_trajectory(unstamped, gt); }).find("paired by index"),
            std::string::npos);
  // A straight line leaves the rotation about it free.
  Trajectory line;
  for (int i = 0; i < 10; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(i, 0, 0);
    line.push_back(i * 100'000'000, T);
  }
  EXPECT_NE(error_of([&] { slam::evaluate_trajectory(line, line); }).find("on a line"),
            std::string::npos);
  slam::TrajectoryEvaluationSettings none;
  none.alignment = Alignment::kNone;
  EXPECT_NO_THROW(slam::evaluate_trajectory(line, line, none));
  const std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 2, 3}};
  EXPECT_NE(error_of([&] { slam::umeyama(two, two, false); }).find("at least 3 pose pairs"),
            std::string::npos);
  EXPECT_NE(error_of([&] { slam::parse_alignment("sim3"); }).find("unknown alignment 'sim3'"),
            std::string::npos);
}

// The KITTI devkit's metric on a 1000 m straight line (1 m per frame) whose estimate runs 1 %
// long: a segment of nominal length L ends at the first frame beyond L, i.e. spans L + 1 m,
// so its error is 0.01 (L + 1) / L.
TEST(TrajectoryMetrics, KittiSegmentsOnAStraightLineOnePercentLong) {
  Trajectory gt;
  Trajectory est;
  for (int i = 0; i <= 1000; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(i, 0, 0);
    gt.push_back(i, T);
    T.translation() *= 1.01;
    est.push_back(i, T);
  }
  const auto kitti = slam::kitti_segment_error(est, gt);
  ASSERT_TRUE(kitti.has_value());
  double sum = 0.0;
  size_t segments = 0;
  for (int length = 100; length <= 800; length += 100) {
    // Starts 0, 10, ... while start + length + 1 <= 1000.
    const int starts = (1000 - length - 1) / 10 + 1;
    sum += starts * 0.01 * (length + 1.0) / length;
    segments += static_cast<size_t>(starts);
  }
  EXPECT_EQ(kitti->segments, segments);
  EXPECT_NEAR(kitti->t_err_pct, 100.0 * sum / static_cast<double>(segments), 1e-9);
  EXPECT_NEAR(kitti->r_err_deg_per_m, 0.0, 1e-9);
}

TEST(TrajectoryMetrics, KittiRotationErrorInDegreesPerMetre) {
  // 201 m straight; the estimate yaws by 0.01 deg more per frame than the ground truth (which
  // does not turn); translation follows the ground truth exactly.
  Trajectory gt;
  Trajectory est;
  for (int i = 0; i <= 200; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(i, 0, 0);
    gt.push_back(i, T);
    T.linear() = Eigen::AngleAxisd(i * 0.01 * M_PI / 180, Eigen::Vector3d::UnitZ()).matrix();
    est.push_back(i, T);
  }
  const auto kitti = slam::kitti_segment_error(est, gt);
  ASSERT_TRUE(kitti.has_value());
  // 100 m segments only (a 200 m one needs 201 m from its start): 10 starts 0..90, each over
  // 101 frames of 0.01 deg.
  EXPECT_EQ(kitti->segments, 10u);
  EXPECT_NEAR(kitti->r_err_deg_per_m, 101 * 0.01 / 100.0, 1e-9);
}

}  // namespace
}  // namespace featsense::test
