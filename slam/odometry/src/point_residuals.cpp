#include "featsense/slam/odometry/point_residuals.hpp"

namespace featsense::slam::odometry {
namespace {

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Vector3d map_point(const double* q, const double* t, const Eigen::Vector3d& p,
                          const Eigen::Vector3d& anchor, double gain) {
  const Eigen::Map<const Eigen::Quaterniond> rotation(q);
  return anchor + gain * (rotation * p + Eigen::Map<const Eigen::Vector3d>(t) - anchor);
}

/// d(residual)/d(tangent) from d(residual)/dx: a left turn w moves x by -[R p]x w.
template <int Rows>
Eigen::Matrix<double, Rows, 6> to_tangent(const Eigen::Matrix<double, Rows, 3>& d_x,
                                          const Eigen::Quaterniond& q, const Eigen::Vector3d& p) {
  Eigen::Matrix<double, Rows, 6> j;
  j.template leftCols<3>() = -d_x * skew(q * p);
  j.template rightCols<3>() = d_x;
  return j;
}

}  // namespace

Eigen::Matrix<double, 3, 4> rotated_point_jacobian(const Eigen::Quaterniond& q,
                                                   const Eigen::Vector3d& p) {
  // R p = p + 2 w (v x p) + 2 v x (v x p) for a unit q = (v, w).
  const Eigen::Vector3d v = q.vec();
  const double w = q.w();
  Eigen::Matrix<double, 3, 4> j;
  j.leftCols<3>() = -2.0 * w * skew(p) + 2.0 * (v.dot(p) * Eigen::Matrix3d::Identity() +
                                                v * p.transpose() - 2.0 * p * v.transpose());
  j.col(3) = 2.0 * v.cross(p);
  return j;
}

void PointToLine::evaluate(const double* q, const double* t, double* residual, double* jacobian_q,
                           double* jacobian_t) const {
  const Eigen::Vector3d x = map_point(q, t, point, anchor, gain);
  Eigen::Map<Eigen::Vector3d> out_residual(residual);
  out_residual = (x - line_point).cross(direction);
  if (jacobian_q == nullptr && jacobian_t == nullptr) return;
  const Eigen::Matrix3d d_x = -gain * skew(direction);  // (x - a) x d = -d x (x - a)
  if (jacobian_q != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> out_jacobian_q(jacobian_q);
    out_jacobian_q = d_x * rotated_point_jacobian(Eigen::Map<const Eigen::Quaterniond>(q), point);
  }
  if (jacobian_t != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> out_jacobian_t(jacobian_t);
    out_jacobian_t = d_x;
  }
}

Eigen::Matrix<double, 3, 6> PointToLine::tangent_jacobian(const Eigen::Quaterniond& q) const {
  return to_tangent<3>(-skew(direction), q, point);
}

void PointToPlane::evaluate(const double* q, const double* t, double* residual, double* jacobian_q,
                            double* jacobian_t) const {
  residual[0] = normal.dot(map_point(q, t, point, anchor, gain)) + offset;
  const Eigen::RowVector3d d_x = gain * normal.transpose();
  if (jacobian_q != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 1, 4>> out_jacobian_q(jacobian_q);
    out_jacobian_q = d_x * rotated_point_jacobian(Eigen::Map<const Eigen::Quaterniond>(q), point);
  }
  if (jacobian_t != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 1, 3>> out_jacobian_t(jacobian_t);
    out_jacobian_t = d_x;
  }
}

Eigen::Matrix<double, 1, 6> PointToPlane::tangent_jacobian(const Eigen::Quaterniond& q) const {
  return to_tangent<1>(normal.transpose(), q, point);
}

}  // namespace featsense::slam::odometry
