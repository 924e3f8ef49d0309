#pragma once
/// One sample of an inertial measurement unit, in the LiDAR's sensor frame.

#include <Eigen/Core>

#include <cstdint>

namespace featsense::slam {

struct ImuSample {
  int64_t stamp_ns = 0;
  /// Specific force, m/s^2: what an accelerometer reads, the acceleration minus gravity's, so
  /// an IMU at rest reads about +9.81 along the up direction.
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();  ///< angular velocity, rad/s
};

}  // namespace featsense::slam
