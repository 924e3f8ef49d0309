#pragma once
/// The tangent the registration works in: a step [w, dt] turns a pose by the rotation vector
/// w (rad, map frame) about the sensor's own position and moves it by dt (m, map frame). The
/// information matrices, degenerate directions and precisions of OdometryResult are in it.

#include <Eigen/Geometry>

namespace featsense::slam::odometry {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// The step from `from` to `to`: to = (Exp(w) R_from, t_from + dt).
Vector6d tangent_between(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to);

/// `from` moved by the step `d`.
Eigen::Isometry3d apply_tangent(const Eigen::Isometry3d& from, const Vector6d& d);

}  // namespace featsense::slam::odometry
