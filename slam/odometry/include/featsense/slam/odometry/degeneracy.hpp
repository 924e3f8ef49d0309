#pragma once
/// Which directions of motion a registration observes (Zhang, Kaess, Singh 2016, "On
/// degeneracy of optimization-based state estimation problems").

#include <Eigen/Core>

#include <vector>

#include "featsense/slam/odometry/pose_tangent.hpp"

namespace featsense::slam::odometry {

struct Degeneracy {
  Vector6d eigenvalues = Vector6d::Zero();       ///< of the information matrix, ascending
  Matrix6d eigenvectors = Matrix6d::Identity();  ///< columns, in the eigenvalues' order
  std::vector<Vector6d> unobservable;            ///< eigenvectors of eigenvalues below threshold
  /// Projects a tangent step onto the observable directions (identity when none is
  /// unobservable).
  Matrix6d observable_projector = Matrix6d::Identity();

  bool degenerate() const { return !unobservable.empty(); }
};

/// `information` is J^T J / N over the N residual rows, in the tangent [rotation (rad),
/// translation (m)]: its eigenvalue along a unit direction is the rows' mean squared change
/// per unit move that way. Directions below `threshold` are unobservable.
Degeneracy analyse_degeneracy(const Matrix6d& information, double threshold);

}  // namespace featsense::slam::odometry
