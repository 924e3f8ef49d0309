#pragma once
// Ground-truth trajectories for the trajectory tests: a 3D path (not on a line) with turning
// orientation, sampled at 10 Hz.

#include <Eigen/Geometry>

#include <cmath>

#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::test {

/// `count` poses: a helix of radius 5 m rising 0.2 m per second, the sensor yawing with it
/// and rolling slightly; stamps from `start_ns` every 100 ms.
inline slam::Trajectory helix_trajectory(size_t count, int64_t start_ns = 1'000'000'000) {
  slam::Trajectory trajectory;
  for (size_t i = 0; i < count; ++i) {
    const double t = 0.1 * static_cast<double>(i);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(5.0 * std::cos(0.3 * t), 5.0 * std::sin(0.3 * t), 0.2 * t);
    T.linear() = (Eigen::AngleAxisd(0.3 * t, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(0.05 * std::sin(t), Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    trajectory.push_back(start_ns + static_cast<int64_t>(i) * 100'000'000, T);
  }
  return trajectory;
}

/// A rigid transform with every component non-zero.
inline Eigen::Isometry3d some_transform() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(12.0, -4.0, 1.5);
  return T;
}

}  // namespace featsense::test
