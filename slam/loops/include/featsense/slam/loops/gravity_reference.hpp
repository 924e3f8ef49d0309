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
  /// The odometry's acceleration over a window errs by this share of itself, alike in every
  /// bend, so that it does not average out: its scale (LiDAR odometry's relative translation
  /// error is 0.5-1 %), and the turn rate times the milliseconds by which a sweep's pose and
  /// its stamp differ (1.3 rad/s in a 3 m bend at 4 m/s: 10 ms is 1.3 %).
  double odometry_acceleration_error = 0.03;
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
  /// The keyframes whose windows share these samples: sigma_rad is one window's error times
  /// the square root of this (each counts for a share).
  double shared = 1.0;
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

/// How the accelerometer's up directions agree with the LiDAR's rotations.
struct GravityAgreement {
  size_t observations = 0;
  /// One window's error as the observations' model says (their median), and as their scatter
  /// about one common tilt and bias says (robust RMS per axis, pooled), radians.
  double model_rad = 0.0;
  double scatter_rad = 0.0;
};

/// Weighs `observations` by how they agree with each other through the rotations of the nodes
/// `R_map_node` (the LiDAR's, which tilt from keyframe to keyframe within a few thousandths of
/// a degree): one common tilt and bias are fitted with the rotations held, and what scatters
/// about them is the observations' real error. Beyond the accelerometer's noise that is the
/// odometry's acceleration over the window, whose positions err together over seconds (a
/// centimetre's wander over a 4 s window is 0.05 deg), not as the white jitter the model
/// assumes. Each sigma is raised to the scatter (never lowered), so that the graph neither
/// bends the LiDAR's relative tilts to that error nor trusts the map's tilt beyond it.
GravityAgreement weigh_gravity_against_lidar(std::vector<GravityObservation>* observations,
                                             const std::vector<Eigen::Matrix3d>& R_map_node,
                                             double bias_prior_mps2);

}  // namespace featsense::slam::loops
