#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

#include "featsense/slam/odometry/pose_tangent.hpp"
#include "featsense/slam/odometry/stand_detector.hpp"

namespace featsense::slam::odometry {
namespace {

/// A registration's precision with the same standard deviation along every direction:
/// `sigma_m` in translation and `sigma_rad` in rotation.
Matrix6d precision_of(double sigma_m, double sigma_rad) {
  Matrix6d p = Matrix6d::Zero();
  p.diagonal() << 1.0 / (sigma_rad * sigma_rad), 1.0 / (sigma_rad * sigma_rad),
      1.0 / (sigma_rad * sigma_rad), 1.0 / (sigma_m * sigma_m), 1.0 / (sigma_m * sigma_m),
      1.0 / (sigma_m * sigma_m);
  return p;
}

Eigen::Isometry3d moved_by(const Eigen::Isometry3d& from, const Vector6d& step) {
  return apply_tangent(from, step);
}

/// A registered pose: `truth` scattered by the noise of `sigma_m` / `sigma_rad`.
Eigen::Isometry3d scattered(const Eigen::Isometry3d& truth, double sigma_m, double sigma_rad,
                            std::mt19937& random) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Vector6d step;
  for (int i = 0; i < 3; ++i) step(i) = sigma_rad * normal(random);
  for (int i = 3; i < 6; ++i) step(i) = sigma_m * normal(random);
  return moved_by(truth, step);
}

TEST(MahalanobisStep, WeighsTheStepByBothPosesCovariances) {
  const Matrix6d p = precision_of(0.01, 0.001);
  Vector6d step = Vector6d::Zero();
  step(3) = 0.01;  // one standard deviation along x
  const Eigen::Isometry3d from = Eigen::Isometry3d::Identity();
  int dimensions = 0;
  // Two equal covariances add up: 1 sigma of one is 1 / 2 in the sum's squared distance.
  EXPECT_NEAR(mahalanobis_step(from, p, moved_by(from, step), p, &dimensions), 0.5, 1e-9);
  EXPECT_EQ(dimensions, 6);
  // A zero precision is the first scan's: its points are as noisy as the other's.
  EXPECT_NEAR(mahalanobis_step(from, Matrix6d::Zero(), moved_by(from, step), p, &dimensions), 0.5,
              1e-9);
  step(3) = 0.0;
  step(2) = 0.002;  // two standard deviations of yaw
  EXPECT_NEAR(mahalanobis_step(from, Matrix6d::Zero(), moved_by(from, step), p, &dimensions), 2.0,
              1e-6);
}

TEST(MahalanobisStep, DirectionsARegistrationDoesNotObserveDoNotCount) {
  Matrix6d blind = precision_of(0.01, 0.001);
  blind(3, 3) = 0.0;  // a corridor along x: nothing pins x down
  Vector6d step = Vector6d::Zero();
  step(3) = 5.0;
  step(4) = 0.01;
  int dimensions = 0;
  const Eigen::Isometry3d from = Eigen::Isometry3d::Identity();
  EXPECT_NEAR(
      mahalanobis_step(from, precision_of(0.01, 0.001), moved_by(from, step), blind, &dimensions),
      0.5, 1e-6);
  EXPECT_EQ(dimensions, 5);
  // Two exact poses: nothing to judge a step by.
  EXPECT_EQ(
      mahalanobis_step(from, Matrix6d::Zero(), moved_by(from, step), Matrix6d::Zero(), &dimensions),
      0.0);
  EXPECT_EQ(dimensions, 0);
}

TEST(ChiSquared, QuantilesOfProbability999) {
  EXPECT_NEAR(chi_squared_999(1), 10.83, 0.01);
  EXPECT_NEAR(chi_squared_999(6), 22.46, 0.01);
  EXPECT_EQ(chi_squared_999(9), chi_squared_999(6));
}

/// The detector over a sensor that stands, registered with noise, then moves off at
/// `speed_m` per scan: the poses given.
struct StandRun {
  std::vector<Eigen::Isometry3d> given;
  std::vector<bool> standing;
  int resumed_at = -1;
};

StandRun run_stand_then_move(int stand_scans, int move_scans, double speed_m, double sigma_m,
                             double sigma_rad, unsigned seed) {
  std::mt19937 random(seed);
  StandDetector detector(2, 2);
  const Matrix6d p = precision_of(sigma_m, sigma_rad);
  StandRun run;
  Eigen::Isometry3d previous = Eigen::Isometry3d::Identity();
  Matrix6d previous_precision = Matrix6d::Zero();  // the first scan defines the map
  run.given.push_back(previous);
  run.standing.push_back(false);
  for (int i = 1; i < stand_scans + move_scans; ++i) {
    Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
    if (i >= stand_scans) truth.translation().x() = speed_m * (i - stand_scans + 1);
    const Eigen::Isometry3d registered = scattered(truth, sigma_m, sigma_rad, random);
    const StandDetector::Verdict verdict =
        detector.update(previous, previous_precision, registered, p, true);
    if (verdict.resumed && run.resumed_at < 0) run.resumed_at = i;
    run.given.push_back(verdict.pose);
    run.standing.push_back(verdict.standing);
    previous = verdict.pose;
    if (!verdict.standing) previous_precision = p;
  }
  return run;
}

TEST(StandDetector, AStandingSensorIsHeldWhereItStood) {
  // 1.5 cm and 0.5 degrees of scatter: a sparse sensor close to walls (a parked HDL-32E).
  const double sigma_m = 0.015;
  const double sigma_rad = 0.5 * M_PI / 180.0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const StandRun run = run_stand_then_move(300, 0, 0.0, sigma_m, sigma_rad, seed);
    int standing = 0;
    for (size_t i = 3; i < run.given.size(); ++i) {
      standing += run.standing[i] ? 1 : 0;
      if (!run.standing[i]) continue;
      // Held exactly at the first pose: the stand began with the first scan.
      EXPECT_TRUE(run.given[i].isApprox(Eigen::Isometry3d::Identity(), 1e-12)) << i;
    }
    // A stand ends only on two scans in a row beyond the 99.9 % quantile: hardly ever.
    EXPECT_GE(standing, 290) << "seed " << seed;
  }
}

TEST(StandDetector, ASensorThatMovesOffResumesWithinTwoScans) {
  const double sigma_m = 0.003;
  const double sigma_rad = 0.001;
  // Walking off at 1 m/s: 0.1 m per scan at 10 Hz, far beyond the noise.
  const StandRun walk = run_stand_then_move(20, 30, 0.1, sigma_m, sigma_rad, 7);
  ASSERT_EQ(walk.resumed_at, 21);
  for (size_t i = 21; i < walk.given.size(); ++i) {
    EXPECT_FALSE(walk.standing[i]) << i;
  }
}

TEST(StandDetector, ACreepingSensorLagsByTheNoiseBoundAtMost) {
  // 1 cm per scan against 3 mm of scatter: each step lies within the noise, so stands start
  // again and again; each ends once the pose has left the noise about it (6.7 sigma of the
  // two poses' noise, two scans in a row). The pose given never lags by much more.
  const double sigma_m = 0.003;
  const StandRun creep = run_stand_then_move(20, 60, 0.01, sigma_m, 0.001, 7);
  ASSERT_GE(creep.resumed_at, 20);
  for (int i = 20; i < 80; ++i) {
    const double truth_m = 0.01 * (i - 19);
    const double lag_m = truth_m - creep.given[static_cast<size_t>(i)].translation().x();
    EXPECT_LT(std::abs(lag_m), 0.04) << i;
  }
}

TEST(StandDetector, AMovingSensorNeverStands) {
  const StandRun run = run_stand_then_move(1, 100, 0.05, 0.003, 0.001, 3);
  for (size_t i = 0; i < run.given.size(); ++i) EXPECT_FALSE(run.standing[i]) << i;
}

TEST(StandDetector, OneOutlierNeitherEndsAStandNorStartsOne) {
  StandDetector detector(2, 2);
  const Matrix6d p = precision_of(0.005, 0.001);
  const Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  EXPECT_FALSE(detector.update(origin, Matrix6d::Zero(), origin, p, true).standing);
  EXPECT_TRUE(detector.update(origin, p, origin, p, true).standing);
  Eigen::Isometry3d off = origin;
  off.translation().y() = 0.2;  // one scan registered 20 cm off: a person walked past
  const StandDetector::Verdict outlier = detector.update(origin, p, off, p, true);
  EXPECT_TRUE(outlier.standing);
  EXPECT_TRUE(outlier.pose.isApprox(origin));
  EXPECT_TRUE(detector.update(origin, p, origin, p, true).standing);
  // A registration that failed says nothing: the stand goes on.
  EXPECT_TRUE(detector.update(origin, p, off, p, false).standing);
  // Two in a row end it, with the registered pose.
  EXPECT_TRUE(detector.update(origin, p, off, p, true).standing);
  const StandDetector::Verdict moved = detector.update(origin, p, off, p, true);
  EXPECT_FALSE(moved.standing);
  EXPECT_TRUE(moved.resumed);
  EXPECT_TRUE(moved.pose.isApprox(off));
}

}  // namespace
}  // namespace featsense::slam::odometry
