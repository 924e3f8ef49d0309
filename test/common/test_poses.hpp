#pragma once
// Poses for registration tests: built from yaw, pitch and roll, and compared by angle.

#include <Eigen/Geometry>

namespace featsense::test {

/// Rotation yaw about z, then pitch about y, then roll about x (radians), and translation t.
inline Eigen::Isometry3d pose(double yaw, double pitch, double roll, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = t;
  return T;
}

/// The angle of the rotation between two poses, radians.
inline double angle_between(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(Eigen::Matrix3d(a.rotation().transpose() * b.rotation())).angle();
}

}  // namespace featsense::test
