#pragma once
/// An inertial measurement unit riding with the simulated LiDAR: specific force and angular
/// velocity from the path's second and first derivatives, with a constant bias and white noise
/// of a MEMS-class unit, drawn from a hash of (seed, sample, axis) like the LiDAR's noise.

#include <cstdint>
#include <vector>

#include "featsense/slam/imu_sample.hpp"
#include "featsense/slam/sim/trajectory.hpp"

namespace featsense::slam {

struct ImuModel {
  bool enabled = true;
  double rate_hz = 100.0;
  /// White noise per sample (standard deviation) and the magnitude of a constant bias whose
  /// direction the seed draws: a consumer-grade MEMS accelerometer and gyroscope.
  double accel_noise_mps2 = 0.02;
  double accel_bias_mps2 = 0.05;
  double gyro_noise_radps = 0.003;
  double gyro_bias_radps = 0.001;

  /// A perfect IMU: no bias, no noise.
  static ImuModel exact();
};

/// Standard gravity, m/s^2.
constexpr double kStandardGravity = 9.80665;

/// The IMU's samples at times k / rate_hz within [t0_s, t1_s) of `path` (seconds from its
/// start), stamped start_stamp_ns + t. The sensor frame is the IMU's; map Z is up.
std::vector<ImuSample> simulate_imu(const PoseCurve& path, const ImuModel& model, uint64_t seed,
                                    double t0_s, double t1_s, int64_t start_stamp_ns);

}  // namespace featsense::slam
