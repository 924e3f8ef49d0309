#pragma once
/// What GyroTwist and gyro_rotation both read from two sweeps' IMU samples.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

#include "featsense/slam/imu_sample.hpp"

namespace featsense::slam::gyro {

/// The gyroscope's rates of two consecutive sweeps (each in time order), their times in
/// seconds from `origin_ns`. A sample out of order or repeated, or not a number, says nothing
/// reliable and is skipped.
struct Rates {
  std::vector<double> times_s;
  std::vector<Eigen::Vector3d> rates;
};

inline Rates merged_rates(const std::vector<ImuSample>& earlier,
                          const std::vector<ImuSample>& later, int64_t origin_ns) {
  Rates out;
  for (const std::vector<ImuSample>* part : {&earlier, &later}) {
    for (const ImuSample& sample : *part) {
      const double time_s = static_cast<double>(sample.stamp_ns - origin_ns) * 1e-9;
      if (!sample.gyro_radps.allFinite() ||
          (!out.times_s.empty() && !(time_s > out.times_s.back()))) {
        continue;
      }
      out.times_s.push_back(time_s);
      out.rates.push_back(sample.gyro_radps);
    }
  }
  return out;
}

/// The rotation of a rotation vector (identity for a zero or non-finite one).
inline Eigen::Matrix3d rotation_of(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (!(angle > 0.0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

}  // namespace featsense::slam::gyro
