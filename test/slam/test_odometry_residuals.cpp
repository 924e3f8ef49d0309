#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

#include "featsense/slam/odometry/degeneracy.hpp"
#include "featsense/slam/odometry/feature_fit.hpp"
#include "featsense/slam/odometry/huber_folding.hpp"
#include "featsense/slam/odometry/point_residuals.hpp"
#include "featsense/slam/odometry/voxel_filter.hpp"

namespace featsense::slam::odometry {
namespace {

/// Exp(w) * q: EigenQuaternionManifold's Plus.
Eigen::Quaterniond plus(const Eigen::Quaterniond& q, const Eigen::Vector3d& w) {
  const double angle = w.norm();
  const Eigen::Quaterniond turn = angle > 0.0
                                      ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, w / angle))
                                      : Eigen::Quaterniond::Identity();
  return turn * q;
}

template <class Residual>
Eigen::VectorXd residual_at(const Residual& r, const Eigen::Quaterniond& q,
                            const Eigen::Vector3d& t) {
  Eigen::VectorXd out(Residual::kResiduals);
  r.evaluate(q.coeffs().data(), t.data(), out.data(), nullptr, nullptr);
  return out;
}

/// The analytic Jacobians against central differences on the manifold.
template <class Residual>
void check_jacobians(const Residual& r, const Eigen::Quaterniond& q, const Eigen::Vector3d& t) {
  constexpr int n = Residual::kResiduals;
  const double h = 1e-6;
  Eigen::Matrix<double, n, 6> numeric;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d w = h * Eigen::Vector3d::Unit(i);
    numeric.col(i) = (residual_at(r, plus(q, w), t) - residual_at(r, plus(q, -w), t)) / (2 * h);
    numeric.col(3 + i) = (residual_at(r, q, t + w) - residual_at(r, q, t - w)) / (2 * h);
  }
  // tangent_jacobian holds the point rigid; a deskewed point moves `gain` times as far.
  const Eigen::Matrix<double, n, 6> tangent = r.gain * r.tangent_jacobian(q);
  EXPECT_LT((tangent - numeric).cwiseAbs().maxCoeff(), 1e-6) << tangent << "\n" << numeric;

  // The ambient Jacobians Ceres gets, through Plus' Jacobian, give the same.
  Eigen::Matrix<double, n, 4, Eigen::RowMajor> jq;
  Eigen::Matrix<double, n, 3, Eigen::RowMajor> jt;
  Eigen::Matrix<double, n, 1> value;
  r.evaluate(q.coeffs().data(), t.data(), value.data(), jq.data(), jt.data());
  Eigen::Matrix<double, 4, 3> plus_jacobian;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d w = h * Eigen::Vector3d::Unit(i);
    plus_jacobian.col(i) = (plus(q, w).coeffs() - plus(q, -w).coeffs()) / (2 * h);
  }
  EXPECT_LT((Eigen::Matrix<double, n, 3>(jq * plus_jacobian) - tangent.template leftCols<3>())
                .cwiseAbs()
                .maxCoeff(),
            1e-6);
  EXPECT_LT(
      (Eigen::Matrix<double, n, 3>(jt) - tangent.template rightCols<3>()).cwiseAbs().maxCoeff(),
      1e-12);
  EXPECT_LT((value - residual_at(r, q, t)).norm(), 1e-15);
}

TEST(OdometryResiduals, JacobiansMatchCentralDifferencesOnTheManifold) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto vec = [&] { return Eigen::Vector3d(u(rng), u(rng), u(rng)); };
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom();
    const Eigen::Vector3d t = 5.0 * vec();
    check_jacobians(PointToLine{10.0 * vec(), 3.0 * vec(), vec().normalized()}, q, t);
    const Eigen::Vector3d n = vec().normalized();
    check_jacobians(PointToPlane{10.0 * vec(), n, u(rng)}, q, t);
    // Deskewed points, coupled to the pose (anchor, gain 1 + s).
    PointToLine line{10.0 * vec(), 3.0 * vec(), vec().normalized()};
    line.anchor = 10.0 * vec();
    line.gain = 1.0 + 0.5 * (u(rng) + 1.0);
    check_jacobians(line, q, t);
    PointToPlane plane{10.0 * vec(), n, u(rng)};
    plane.anchor = 10.0 * vec();
    plane.gain = 1.0 + 0.5 * (u(rng) + 1.0);
    check_jacobians(plane, q, t);
  }
}

TEST(OdometryResiduals, ACoupledPointMovesGainTimesAsFarAsTheRigidOne) {
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d t0(1.0, 2.0, 0.5);
  PointToPlane rigid{Eigen::Vector3d(4.0, -1.0, 0.3), Eigen::Vector3d(1, 2, 2).normalized(), 0.7};
  PointToPlane coupled = rigid;
  coupled.anchor = q0 * rigid.point + t0;  // where the point lies at the pose it was deskewed at
  coupled.gain = 1.75;
  // At that pose both agree; away from it the coupled residual changes 1.75 times as much.
  EXPECT_NEAR(residual_at(coupled, q0, t0)(0), residual_at(rigid, q0, t0)(0), 1e-12);
  const Eigen::Quaterniond q1 = plus(q0, Eigen::Vector3d(0.01, -0.02, 0.03));
  const Eigen::Vector3d t1 = t0 + Eigen::Vector3d(0.05, -0.02, 0.01);
  const double rigid_change = residual_at(rigid, q1, t1)(0) - residual_at(rigid, q0, t0)(0);
  const double coupled_change = residual_at(coupled, q1, t1)(0) - residual_at(coupled, q0, t0)(0);
  EXPECT_NEAR(coupled_change, 1.75 * rigid_change, 1e-12);
}

/// Huber's rho(s) as Ceres' HuberLoss defines it.
double huber_rho(double s, double delta) {
  return s <= delta * delta ? s : 2.0 * delta * std::sqrt(s) - delta * delta;
}

TEST(OdometryHuberFolding, SameCostAndGradientAsTheLossAndExactJacobians) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto vec = [&] { return Eigen::Vector3d(u(rng), u(rng), u(rng)); };
  const double delta = 0.1;
  for (int trial = 0; trial < 40; ++trial) {
    PointToLine line{10.0 * vec(), 3.0 * vec(), vec().normalized()};
    line.anchor = 10.0 * vec();
    line.gain = 1.3;
    const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom();
    // Near and far from the line: both sides of the loss's kink.
    const Eigen::Vector3d t = (trial % 2 == 0 ? 0.02 : 2.0) * vec();
    auto folded = [&](const Eigen::Quaterniond& qq, const Eigen::Vector3d& tt,
                      Eigen::Matrix<double, 3, 4, Eigen::RowMajor>* jq,
                      Eigen::Matrix<double, 3, 3, Eigen::RowMajor>* jt) {
      Eigen::Vector3d r;
      line.evaluate(qq.coeffs().data(), tt.data(), r.data(), jq ? jq->data() : nullptr,
                    jt ? jt->data() : nullptr);
      fold_huber(delta, 3, r.data(), jq ? jq->data() : nullptr, jt ? jt->data() : nullptr);
      return r;
    };
    Eigen::Vector3d raw;
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> raw_jq;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> raw_jt;
    line.evaluate(q.coeffs().data(), t.data(), raw.data(), raw_jq.data(), raw_jt.data());
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> jq;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> jt;
    const Eigen::Vector3d r = folded(q, t, &jq, &jt);
    const double s = raw.squaredNorm();
    // The same cost ...
    EXPECT_NEAR(r.squaredNorm(), huber_rho(s, delta), 1e-12);
    // ... the same gradient, rho'(s) J^T r ...
    const double rho1 = s <= delta * delta ? 1.0 : delta / std::sqrt(s);
    EXPECT_LT((jt.transpose() * r - rho1 * raw_jt.transpose() * raw).norm(), 1e-9);
    EXPECT_LT((jq.transpose() * r - rho1 * raw_jq.transpose() * raw).norm(), 1e-9);
    // ... and the Jacobian of the folded residual, by central differences in t.
    const double h = 1e-7;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(i);
      const Eigen::Vector3d numeric =
          (folded(q, t + e, nullptr, nullptr) - folded(q, t - e, nullptr, nullptr)) / (2 * h);
      EXPECT_LT((numeric - jt.col(i)).norm(), 1e-6) << trial;
    }
  }
}

TEST(OdometryResiduals, DistancesAreThoseOfTheGeometry) {
  const Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  const Eigen::Vector3d t(0, 0, 1);
  // (1, 2, 0) + t = (1, 2, 1): 2 m from the x axis... shifted to y = 0, z = 0.
  const Eigen::VectorXd line =
      residual_at(PointToLine{{1, 2, 0}, {0, 0, 0}, Eigen::Vector3d::UnitX()}, q, t);
  EXPECT_NEAR(line.norm(), std::sqrt(5.0), 1e-12);
  const Eigen::VectorXd plane =
      residual_at(PointToPlane{{1, 2, 0}, Eigen::Vector3d::UnitZ(), -0.25}, q, t);
  EXPECT_NEAR(plane(0), 0.75, 1e-12);
}

TEST(OdometryFit, LinesAndPlanesFollowTheEigenvalueRules) {
  std::vector<Eigen::Vector3d> line, plane, blob;
  for (int i = 0; i < 5; ++i) line.emplace_back(0.3 * i, 1.0, 2.0);
  const auto l = fit_line(line);
  ASSERT_TRUE(l.has_value());
  EXPECT_NEAR(std::abs(l->direction.x()), 1.0, 1e-12);
  EXPECT_FALSE(fit_plane(line).has_value());  // collinear: no plane
  for (int i = 0; i < 5; ++i) plane.emplace_back(0.3 * (i % 3), 0.4 * (i / 3), 1.0);
  const auto p = fit_plane(plane);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(std::abs(p->normal.z()), 1.0, 1e-12);
  EXPECT_NEAR(p->normal.z() * 1.0 + p->offset, 0.0, 1e-12);
  EXPECT_FALSE(fit_line(plane).has_value());
  // A neighbour 0.3 m off the plane (beyond F-LOAM's 0.2 m) rejects it.
  const std::vector<Eigen::Vector3d> bent = {
      {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0.5, 0.5, 0.3}};
  EXPECT_FALSE(fit_plane(bent).has_value());
  EXPECT_TRUE(fit_plane(bent, 0.3).has_value());
  blob = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  EXPECT_FALSE(fit_line(blob).has_value());
  EXPECT_FALSE(fit_plane(blob).has_value());
}

TEST(OdometryDegeneracy, SmallEigenvaluesAreUnobservableDirections) {
  Matrix6d info = Matrix6d::Identity();
  info(3, 3) = 1e-4;  // translation along x
  const Degeneracy d = analyse_degeneracy(info, 0.02);
  ASSERT_EQ(d.unobservable.size(), 1u);
  EXPECT_NEAR(std::abs(d.unobservable[0](3)), 1.0, 1e-12);
  Vector6d step = Vector6d::Ones();
  const Vector6d kept = d.observable_projector * step;
  EXPECT_NEAR(kept(3), 0.0, 1e-12);
  EXPECT_NEAR(kept(0), 1.0, 1e-12);
  EXPECT_FALSE(analyse_degeneracy(Matrix6d::Identity(), 0.02).degenerate());
}

TEST(OdometryVoxelFilter, OnePointPerVoxelAndNoNaN) {
  const std::vector<Eigen::Vector3f> points = {{0.1f, 0.1f, 0.1f},
                                               {0.2f, 0.2f, 0.2f},
                                               {-0.1f, 0.1f, 0.1f},
                                               {NAN, 0.f, 0.f},
                                               {0.5f, 0.f, 0.f}};
  const auto kept = voxel_filter(points, 0.4);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0], points[0]);
  EXPECT_EQ(kept[1], points[2]);
  EXPECT_EQ(kept[2], points[4]);

  // The timed variant keeps each kept point's own time, and 0 where no times are given.
  const std::vector<float> times = {0.01f, 0.02f, 0.03f, 0.04f, 0.05f};
  std::vector<float> kept_times;
  const auto timed = voxel_filter(points, times, 0.4, &kept_times);
  ASSERT_EQ(timed, kept);
  EXPECT_EQ(kept_times, (std::vector<float>{0.01f, 0.03f, 0.05f}));
  voxel_filter(points, {}, 0.4, &kept_times);
  EXPECT_EQ(kept_times, (std::vector<float>{0.0f, 0.0f, 0.0f}));
}

}  // namespace
}  // namespace featsense::slam::odometry
