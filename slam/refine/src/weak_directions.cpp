#include "featsense/slam/refine/weak_directions.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace featsense::slam::refine {

namespace {

/// Nothing known of the pose: every direction keeps the guess.
WeakDirections every_direction_weak() {
  WeakDirections weak;
  weak.keep_strong.setZero();
  weak.count = 6;
  weak.weakest_ratio = 0.0;
  return weak;
}

}  // namespace

WeakDirections weak_directions(const Eigen::Matrix<double, 6, 6>& hessian, double lever_arm_m,
                               double min_ratio) {
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  WeakDirections weak;
  if (!(min_ratio > 0.0)) return weak;
  if (!hessian.allFinite() || !(lever_arm_m > 0.0) || !std::isfinite(lever_arm_m))
    return every_direction_weak();
  // In coordinates where a turn is measured as the motion at the lever arm (u = S^-1 x), the
  // Hessian is S H S, and a step projected there is S P S^-1 in the original coordinates.
  Vector6d scale;
  scale << 1.0 / lever_arm_m, 1.0 / lever_arm_m, 1.0 / lever_arm_m, 1.0, 1.0, 1.0;
  const Matrix6d S = scale.asDiagonal();
  const Matrix6d scaled = S * (0.5 * (hessian + hessian.transpose())) * S;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(scaled);
  const Vector6d values = eigen.eigenvalues();  // ascending
  const double largest = values(5);
  if (!(largest > 0.0)) return every_direction_weak();
  weak.weakest_ratio = std::max(values(0), 0.0) / largest;
  Matrix6d projector = Matrix6d::Identity();
  for (int k = 0; k < 6; ++k) {
    if (values(k) < min_ratio * largest) {
      const Vector6d direction = eigen.eigenvectors().col(k);
      projector -= direction * direction.transpose();
      ++weak.count;
    }
  }
  weak.keep_strong = S * projector * S.inverse();
  return weak;
}

}  // namespace featsense::slam::refine
