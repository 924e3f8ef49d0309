#pragma once
/// The registration's residuals with their analytic Jacobians, Eigen only (the Ceres cost
/// functions in src/ wrap them). The pose is a unit quaternion q (Eigen's coefficient order
/// x, y, z, w, as Ceres' EigenQuaternionManifold) and a translation t: x = R(q) p + t takes a
/// sensor point p into the map. Jacobians are row-major, as Ceres wants them, with respect
/// to the ambient parameters (4 of q, 3 of t); `tangent_jacobian` gives them with respect to
/// the 6-D tangent [rotation (left: R <- Exp(w) R, so a turn about the sensor in the map
/// frame), translation], the coordinates of EigenQuaternionManifold's Plus.
///
/// Deskewing couples a point to the pose: a point measured the fraction s of the period
/// between scans after the stamp is moved to the stamp with the motion that the pose implies
/// since the last scan, so when the pose moves, the point moves (1 + s) times as far (to first
/// order; both the pose and the motion change). `anchor` (where the point lies at the pose
/// it was deskewed with) and `gain` (1 + s) model that: x = anchor + gain (R p + t - anchor).
/// With gain 1 the point is rigid. Without the coupling every outer loop would only recover
/// about half of the remaining error.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace featsense::slam::odometry {

/// d(R(q) p)/dq in the ambient coordinates (x, y, z, w) of a unit quaternion.
Eigen::Matrix<double, 3, 4> rotated_point_jacobian(const Eigen::Quaterniond& q,
                                                   const Eigen::Vector3d& p);

/// The distance of a scan point from a map line, as the vector (x - a) x d, whose norm is the
/// distance and which is smooth where the distance is 0.
struct PointToLine {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();       ///< sensor frame
  Eigen::Vector3d line_point = Eigen::Vector3d::Zero();  ///< a, map frame
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< d, unit, map frame
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();      ///< map frame
  double gain = 1.0;

  static constexpr int kResiduals = 3;
  /// residual (3), jacobian_q (3x4, row-major) and jacobian_t (3x3, row-major); the
  /// Jacobians may be null.
  void evaluate(const double* q, const double* t, double* residual, double* jacobian_q,
                double* jacobian_t) const;
  /// d(residual)/d(tangent) of the point held rigid (gain 1): what the geometry observes,
  /// for the information matrix.
  Eigen::Matrix<double, 3, 6> tangent_jacobian(const Eigen::Quaterniond& q) const;
};

/// The signed distance of a scan point from a map plane n . x + offset = 0.
struct PointToPlane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    ///< sensor frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< n, unit, map frame
  double offset = 0.0;
  Eigen::Vector3d anchor = Eigen::Vector3d::Zero();  ///< map frame
  double gain = 1.0;

  static constexpr int kResiduals = 1;
  /// residual (1), jacobian_q (1x4) and jacobian_t (1x3); the Jacobians may be null.
  void evaluate(const double* q, const double* t, double* residual, double* jacobian_q,
                double* jacobian_t) const;
  /// As PointToLine's: the point held rigid.
  Eigen::Matrix<double, 1, 6> tangent_jacobian(const Eigen::Quaterniond& q) const;
};

}  // namespace featsense::slam::odometry
