#pragma once
/// What the registration of one scan gives: the pose, the motion since the last scan and
/// how it was found.

#include <Eigen/Geometry>

#include <cstddef>
#include <string>
#include <vector>

#include "featsense/slam/scan_locator.hpp"
#include "featsense/slam/trajectory/sweep_motion.hpp"

namespace featsense::slam::odometry {

struct OdometryResult {
  /// The sensor's pose at the scan's stamp (map <- sensor). Never NaN: where the solve
  /// cannot be trusted it is the constant-velocity prediction.
  Eigen::Isometry3d T_map_sensor = Eigen::Isometry3d::Identity();
  /// The motion since the previous scan (previous sensor <- this sensor); identity for the
  /// first scan.
  Eigen::Isometry3d T_previous_sensor = Eigen::Isometry3d::Identity();
  double elapsed_s = 0.0;  ///< time since the previous scan (0 for the first)
  /// The motion within the scan, as its features went into the map: T_previous_sensor over
  /// elapsed_s, bent by the gyroscope where the scan had IMU samples; not moving for the
  /// first scan and a scan whose stamp did not advance.
  SweepMotion sweep;

  /// converged, iterations (Ceres iterations in all), degenerate, fitness_m (mean
  /// point-to-line / point-to-plane distance of the correspondences at the result).
  LocateDiagnostics diagnostics;
  /// Why the result is not converged, degenerate, or the first scan; empty otherwise.
  std::string reason;
  /// The unobservable directions, unit 6-vectors in the pose's tangent [rotation (rad, in
  /// the map frame, about the sensor), translation (m, map frame)]: the pose keeps the
  /// prediction along them.
  std::vector<Eigen::Matrix<double, 6, 1>> degenerate_directions;
  /// The eigenvalues of J^T J / N at the result, ascending (see degeneracy_threshold).
  Eigen::Matrix<double, 6, 1> information_eigenvalues = Eigen::Matrix<double, 6, 1>::Zero();
  /// The inverse covariance of the registered pose in the same tangent: J^T J / s^2 over all
  /// residual rows, s^2 their mean square (each clipped at the Huber scale, as the loss
  /// counts it). Zero where nothing was registered (the first scan, a failed solve).
  Eigen::Matrix<double, 6, 6> precision = Eigen::Matrix<double, 6, 6>::Zero();
  /// The scan was taken while the sensor stood still: its pose is the stand's (see
  /// StandDetector), and it did not go into the local map.
  bool standing = false;
  /// The registration fitted far worse than the last scans' (odometry.poor_fit_ratio) and was
  /// searched again from turned starts (odometry.turn_search); found: one of them gave the pose.
  bool turn_searched = false;
  bool turn_found = false;

  size_t scan_edges = 0;               ///< the scan's edges after the voxel filter
  size_t scan_surfaces = 0;            ///< the scan's surfaces after the voxel filter
  size_t edge_correspondences = 0;     ///< in the last outer loop
  size_t surface_correspondences = 0;  ///< in the last outer loop
  size_t map_edges = 0;                ///< the local map after this scan was added
  size_t map_surfaces = 0;

  /// Where the registration's time went, milliseconds.
  struct Timing {
    double association_ms = 0.0;  ///< nearest neighbours and line / plane fits, all loops
    double solve_ms = 0.0;        ///< Ceres, all loops
    double map_update_ms = 0.0;   ///< adding the scan to the local map, pruning, the trees
  } timing;
};

}  // namespace featsense::slam::odometry
