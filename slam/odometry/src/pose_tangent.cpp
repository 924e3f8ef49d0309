#include "featsense/slam/odometry/pose_tangent.hpp"

namespace featsense::slam::odometry {

Vector6d tangent_between(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to) {
  const Eigen::AngleAxisd turn(Eigen::Matrix3d(to.rotation() * from.rotation().transpose()));
  Vector6d d;
  d.head<3>() = turn.angle() * turn.axis();
  d.tail<3>() = to.translation() - from.translation();
  return d;
}

Eigen::Isometry3d apply_tangent(const Eigen::Isometry3d& from, const Vector6d& d) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  const double angle = d.head<3>().norm();
  const Eigen::Matrix3d turn =
      angle > 0.0 ? Eigen::AngleAxisd(angle, d.head<3>() / angle).toRotationMatrix()
                  : Eigen::Matrix3d::Identity();
  out.linear() = turn * from.rotation();
  out.translation() = from.translation() + d.tail<3>();
  return out;
}

}  // namespace featsense::slam::odometry
