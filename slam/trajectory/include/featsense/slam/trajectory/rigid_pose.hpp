#pragma once
/// A pose whose rotation is made exactly orthonormal again. A product of poses leaves SO(3) by
/// rounding, and Eigen's Isometry takes the rotation as it is (its inverse is the transpose).
/// Where a pose is moved by a correction that was measured from the pose itself (a session
/// moved along by each link found from its current estimate), the deviation is raised to the
/// third power at every step: after twenty such steps a 1e-6 deviation is a scale error of
/// several percent, which stretches every cloud placed by the pose.

#include <Eigen/Geometry>

namespace featsense::slam {

inline Eigen::Isometry3d orthonormalised(const Eigen::Isometry3d& T) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  out.translation() = T.translation();
  return out;
}

}  // namespace featsense::slam
