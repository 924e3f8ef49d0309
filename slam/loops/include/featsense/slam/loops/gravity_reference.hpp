#pragma once
/// Gravity as the pose graph's vertical reference. A LiDAR alone cannot see which way is up:
/// a tilt of a few hundredths of a degree in the odometry's first metres tilts the whole map,
/// and every loop ties the rest to it. An IMU's accelerometer measures the specific force
/// f = R^T (a + g up); averaged over a window around a keyframe and turned into the keyframe's
/// frame with the odometry's relative rotations, less the odometry's acceleration over the
/// window (the same weighted mean of it, from a quadratic fitted to every position in the
/// window), it leaves the up direction in that frame:
///   up_k = mean_s(R_k^T R_s f_s) - mean_s(R_k^T R_s) b - R_k^T a_odometry,
/// with b the accelerometer's constant bias (a graph variable, observable once the path turns).
/// Only relative rotations and positions of the odometry enter, which it measures well; the
/// window's length averages the accelerometer's noise.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/imu_sample.hpp"

namespace featsense::slam::loops {

struct GravitySettings {
  bool enabled = config::LoopConfig{}.gravity;  ///< loop.gravity
  /// The IMU samples averaged around each keyframe, seconds (loop.gravity_window).
  double window_s = config::LoopConfig{}.gravity_window_s;
  /// The accelerometer's white noise per sample, and the error of each of the odometry's
  /// positions against its neighbours' (its scan-to-scan jitter, not its drift).
  double accel_noise_mps2 = 0.02;
  double position_sigma_m = 0.005;
  /// A floor on each observation's error (what the model leaves out), m/s^2.
  double min_sigma_mps2 = 0.002;
  /// The prior on the accelerometer's bias, m/s^2 per axis.
  double bias_prior_mps2 = 0.2;
};

/// The up direction seen around one keyframe (graph node), in its sensor frame, as a function
/// of the bias b: mean_force - bias_rotation * b - path_acceleration.
struct GravityObservation {
  size_t node = 0;
  Eigen::Vector3d mean_force = Eigen::Vector3d::Zero();
  Eigen::Matrix3d bias_rotation = Eigen::Matrix3d::Identity();
  /// The odometry's acceleration over the window, weighted as mean_force is.
  Eigen::Vector3d path_acceleration = Eigen::Vector3d::Zero();
  double sigma_rad = 1.0;  ///< the direction's standard deviation per axis, radians
  size_t samples = 0;

  /// Up in the keyframe's frame for bias `bias` (not normalised).
  Eigen::Vector3d up(const Eigen::Vector3d& bias = Eigen::Vector3d::Zero()) const {
    return mean_force - bias_rotation * bias - path_acceleration;
  }
};

/// The IMU's sample period from the median spacing of `samples` (at least two, time order):
/// robust to a gap or a late sample.
int64_t median_sample_period_ns(const std::vector<ImuSample>& samples);

/// Appends `more` to `log`, keeping time order: a sample not after the last one is dropped.
void append_in_time_order(std::vector<ImuSample>* log, const std::vector<ImuSample>& more);

/// The observations of the keyframes stamped `keyframe_stamps_ns` (increasing; node i =
/// keyframe i), from
/// the IMU's `samples` (time order) and the odometry's `path` (stamps increasing, poses
/// T_map_sensor). A keyframe whose window holds too few samples (the IMU started late, a gap)
/// gets none.
std::vector<GravityObservation> gravity_observations(const std::vector<int64_t>& path_stamps_ns,
                                                     const std::vector<Eigen::Isometry3d>& path,
                                                     const std::vector<ImuSample>& samples,
                                                     const std::vector<int64_t>& keyframe_stamps_ns,
                                                     const GravitySettings& settings);

}  // namespace featsense::slam::loops
