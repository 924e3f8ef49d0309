#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <vector>

#include "common/test_data.hpp"
#include "common/test_poses.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/refine/vgicp.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "scene_sampling.hpp"

namespace featsense::slam::refine {
namespace {

using test::pose;
using test::sample_scene;

double angle_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return test::angle_between(a, b) * 180.0 / M_PI;
}

std::vector<Eigen::Vector3f> moved(const std::vector<Eigen::Vector3f>& points,
                                   const Eigen::Isometry3d& T) {
  std::vector<Eigen::Vector3f> out;
  for (const auto& p : points) out.push_back((T * p.cast<double>()).cast<float>());
  return out;
}

TEST(GaussianCloud, ANormalsAlignmentIsTheOneAnEigenSolverFinds) {
  // Points of a tilted roof, a wall and a rough slope, their covariances turned as a sensor's.
  std::mt19937 random(5);
  std::uniform_real_distribution<float> along(-2.0f, 2.0f), noise(-0.01f, 0.01f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 300; ++i) {
    const float a = along(random), b = along(random);
    points.emplace_back(a, b, 0.3f * a + noise(random));
    points.emplace_back(5.0f + noise(random), a, b);
    points.emplace_back(a, 6.0f + 0.8f * b + 0.2f * a, b + noise(random) * 10.0f);
  }
  const GaussianCloud cloud = with_covariances(points, 10);
  ASSERT_GT(cloud.size(), 800u);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  const Eigen::Vector3d direction = Eigen::Vector3d(0.2, 0.4, 1.0).normalized();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Matrix3d turned = R * cloud.covariances[i] * R.transpose();
    eigen.compute(turned);
    EXPECT_NEAR(normal_alignment(turned, direction),
                std::abs(eigen.eigenvectors().col(0).dot(direction)), 1e-6)
        << "point " << i;
    // Any multiple of it alike.
    EXPECT_NEAR(normal_alignment(3.0 * turned, direction), normal_alignment(turned, direction),
                1e-9);
  }
}

TEST(Vgicp, GradientAndHessianMatchTheCost) {
  const mesh::TriangleMesh lab = build_scene("lab");
  const auto a = sample_scene(lab, {0, 0, 1.5f}, 8.0f, 4000, 0.01f, 1);
  const auto b = sample_scene(lab, {0, 0, 1.5f}, 8.0f, 1000, 0.01f, 2);
  const VoxelGaussians target(with_covariances(a, 10), 1.0);
  GaussianCloud source = with_covariances(b, 10);
  // Without source covariances the weights do not turn with the pose: the cost is then
  // exactly the quadratic form whose derivatives linearize() gives.
  for (auto& c : source.covariances) c.setZero();
  const Eigen::Isometry3d T = pose(0.02, -0.01, 0.01, {0.05, -0.03, 0.02});
  const VgicpLinearization at = linearize(target, source, T);
  ASSERT_GT(at.terms, 500u);
  const double h = 1e-6;
  auto step = [&](int k, double s) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d[k] = s;
    const Eigen::Vector3d w = d.head<3>();
    Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
    const Eigen::Matrix3d turn =
        w.norm() > 0 ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                     : Eigen::Matrix3d::Identity();
    out.linear() = turn * T.rotation();
    out.translation() = turn * T.translation() + d.tail<3>();
    return linearize(target, source, out).cost;
  };
  for (int k = 0; k < 6; ++k) {
    const double numeric = (step(k, h) - step(k, -h)) / (2 * h);
    EXPECT_NEAR(numeric, 2.0 * at.gradient[k], 1e-4 * std::max(1.0, std::abs(numeric))) << k;
  }
  // The Gauss-Newton Hessian is symmetric and positive definite on a 3D scene.
  EXPECT_LT((at.hessian - at.hessian.transpose()).norm(), 1e-9 * at.hessian.norm());
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(at.hessian).eigenvalues().minCoeff(), 0.0);
}

TEST(Vgicp, RecoversAKnownMotionFromHalfAMetreAndFiveDegrees) {
  const mesh::TriangleMesh lab = build_scene("lab");
  // Two independent noisy samplings of the same place; the source seen from a sensor moved
  // by `truth` (target <- source).
  const auto a = sample_scene(lab, {0, 0, 1.5f}, 10.0f, 30000, 0.01f, 3);
  const auto b = sample_scene(lab, {0, 0, 1.5f}, 10.0f, 15000, 0.01f, 4);
  const Eigen::Isometry3d truth = pose(0.3, 0.02, -0.01, {1.2, -0.4, 0.1});
  const int k = 20;
  const GaussianCloud target_cloud = with_covariances(a, k);
  const GaussianCloud source = with_covariances(moved(b, truth.inverse()), k);
  const Eigen::Isometry3d guess = truth * pose(5.0 * M_PI / 180.0, 0, 0, {0.4, -0.3, 0.0});
  ASSERT_NEAR((guess.translation() - truth.translation()).norm(), 0.5, 0.05);
  const VgicpResult r = align(target_cloud, source, guess);
  RecordProperty("error_m",
                 std::to_string((r.T_target_source.translation() - truth.translation()).norm()));
  RecordProperty("error_deg", std::to_string(angle_deg(r.T_target_source, truth)));
  RecordProperty("fitness_m", std::to_string(r.fitness_m));
  RecordProperty("inliers", std::to_string(r.inlier_fraction));
  EXPECT_TRUE(r.converged);
  EXPECT_LT((r.T_target_source.translation() - truth.translation()).norm(), 0.01)
      << r.T_target_source.translation().transpose();
  EXPECT_LT(angle_deg(r.T_target_source, truth), 0.1);
  EXPECT_GT(r.inlier_fraction, 0.9);
  EXPECT_LT(r.fitness_m, 0.03);  // the samplings' noise: 1 cm per axis
}

/// The lab seen again after a change: a third of the source's points (those beyond x = 4 m:
/// furniture moved, a door closed) lie 0.3 m above where the target holds that surface. The
/// error of the registration from a guess 5 cm off, least squares or under Geman-McClure's
/// kernel of `robust_scale`.
double changed_scene_error(double robust_scale) {
  const mesh::TriangleMesh lab = build_scene("lab");
  const auto a = sample_scene(lab, {0, 0, 1.5f}, 10.0f, 30000, 0.01f, 3);
  auto b = sample_scene(lab, {0, 0, 1.5f}, 10.0f, 15000, 0.01f, 4);
  size_t changed = 0;
  for (auto& p : b) {
    if (p.x() > 4.0f) {
      p.z() += 0.3f;
      ++changed;
    }
  }
  EXPECT_GT(changed, b.size() / 4);
  EXPECT_LT(changed, b.size() / 2);
  const Eigen::Isometry3d truth = pose(0.1, 0.0, 0.0, {0.5, 0.2, 0.0});
  const GaussianCloud target = with_covariances(a, 20);
  const GaussianCloud source = with_covariances(moved(b, truth.inverse()), 20);
  VgicpSettings settings;
  settings.robust_scale = robust_scale;
  const Eigen::Isometry3d guess = truth * pose(0.0, 0.0, 0.0, {0.03, -0.03, 0.02});
  const VgicpResult r = align(target, source, guess, settings);
  EXPECT_TRUE(r.converged);
  return (r.T_target_source.translation() - truth.translation()).norm();
}

TEST(Vgicp, ARobustKernelLetsAChangedPartOfTheSceneGo) {
  // Least squares meets the changed points halfway; the kernel of the localizer's tracking
  // (LocalizerSettings::tracking_vgicp) weighs them by a thousandth and less.
  const double plain = changed_scene_error(0.0);
  const double robust = changed_scene_error(1.0);
  std::printf("error with a third of the scene changed: %.4f m least squares, %.4f m robust\n",
              plain, robust);
  EXPECT_GT(plain, 0.05);
  EXPECT_LT(robust, 0.005);
}

TEST(Vgicp, AGuessGoodToCentimetresNeedsNoCoarseLevel) {
  const mesh::TriangleMesh lab = build_scene("lab");
  const auto a = sample_scene(lab, {0, 0, 1.5f}, 10.0f, 30000, 0.01f, 5);
  const auto b = sample_scene(lab, {0, 0, 1.5f}, 10.0f, 15000, 0.01f, 6);
  const Eigen::Isometry3d truth = pose(0.3, 0.02, -0.01, {1.2, -0.4, 0.1});
  const GaussianCloud source = with_covariances(moved(b, truth.inverse()), 20);
  VgicpSettings settings;
  settings.voxel_sizes_m = {1.0, 0.5, 0.25};
  const VgicpTarget target(with_covariances(a, 20), settings);
  const Eigen::Isometry3d near = truth * pose(0.5 * M_PI / 180.0, 0, 0, {0.04, -0.03, 0.0});
  for (const size_t first_level : {size_t{0}, size_t{1}, size_t{2}, size_t{9}}) {
    const VgicpResult r = align(target, source, near, settings, first_level);
    EXPECT_LT((r.T_target_source.translation() - truth.translation()).norm(), 0.01) << first_level;
    EXPECT_LT(angle_deg(r.T_target_source, truth), 0.1) << first_level;
    EXPECT_GT(r.inlier_fraction, 0.9) << first_level;  // measured at the finest level
  }
  // From the finest level alone fewer iterations than from the coarsest.
  EXPECT_LT(align(target, source, near, settings, 2).iterations,
            align(target, source, near, settings, 0).iterations);
}

TEST(Vgicp, EmptyCloudsGiveTheGuessNotConverged) {
  const Eigen::Isometry3d guess = pose(0.1, 0, 0, {1, 2, 3});
  const VgicpResult r = align(GaussianCloud{}, GaussianCloud{}, guess);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(r.T_target_source.isApprox(guess));
}

/// The two real HDL-32E scans of data/velodyne and the motion between them.
TEST(Vgicp, RealHdl32PairFromTheIdentity) {
  FEATSENSE_SHARED_FILE(dir, "velodyne");
  FEATSENSE_SHARED_FILE(relative_file, "velodyne/relative.txt");
  auto read_points = [&](const char* name) {
    SourceOptions options;
    options.sensor_preset = "hdl32";
    auto source = open_scan_source((dir / name).string(), options);
    std::vector<Eigen::Vector3f> points;
    while (auto scan = source->next()) {
      for (size_t i = 0; i < scan->size(); ++i)
        if (scan->valid[i]) points.push_back(scan->xyz[i]);
    }
    return points;
  };
  const auto first = read_points("251370668.pcd");
  const auto second = read_points("251371071.pcd");
  ASSERT_GT(first.size(), 10000u);
  Eigen::Matrix4d relative;
  std::ifstream file(relative_file);
  for (int i = 0; i < 16; ++i) file >> relative(i / 4, i % 4);
  const Eigen::Isometry3d truth(relative);
  const int k = 20;
  const GaussianCloud target_cloud = with_covariances(first, k);
  const GaussianCloud source = with_covariances(second, k);
  const VgicpResult r = align(target_cloud, source, Eigen::Isometry3d::Identity());
  RecordProperty("error_m",
                 std::to_string((r.T_target_source.translation() - truth.translation()).norm()));
  RecordProperty("error_deg", std::to_string(angle_deg(r.T_target_source, truth)));
  EXPECT_TRUE(r.converged);
  EXPECT_LT((r.T_target_source.translation() - truth.translation()).norm(), 0.03)
      << r.T_target_source.translation().transpose() << " vs " << truth.translation().transpose();
  EXPECT_LT(angle_deg(r.T_target_source, truth), 0.2);
}

}  // namespace
}  // namespace featsense::slam::refine
