#pragma once
/// The front end's stage with estimated poses: each scan's features extracted
/// (slam/features), registered against the local feature map (FeatureOdometry), and the scan
/// placed with the motion over it, so that the map integrates it deskewed.

#include <Eigen/Geometry>

#include <cstddef>
#include <memory>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/scan_locator.hpp"

namespace featsense::slam::odometry {

/// What the odometry has done so far, for the log and the report.
struct OdometryCounts {
  size_t scans = 0;
  size_t degenerate_scans = 0;  ///< a direction of motion held at the prediction
  size_t failed_scans = 0;      ///< the pose is the prediction (the reason is logged)
  size_t turn_searches = 0;     ///< poor fits searched again from turned starts
  size_t turns_found = 0;       ///< ... where a turned start gave the pose
  size_t time_jumps = 0;        ///< frames dropped, or a stamp that did not grow
  size_t stands = 0;            ///< times the sensor stood still (odometry.hold_still)
  size_t standing_scans = 0;    ///< scans whose pose was held while it stood
  double standing_s = 0.0;      ///< the time between them and the scan before each
  size_t intensity_confirmed_scans = 0;
  double features_sum = 0.0;            ///< edge + surface points, summed over scans
  std::vector<double> features_ms;      ///< per scan: the feature extraction
  std::vector<double> registration_ms;  ///< per scan: the registration and the map update
  /// Per scan, the registration's parts: associations, solves, the local map's update.
  std::vector<double> association_ms;
  std::vector<double> solve_ms;
  std::vector<double> map_update_ms;
  std::vector<double> features_per_scan;  ///< edge + surface points of each scan
  /// The local feature map after the last scan (bounded by odometry.map_radius).
  size_t map_edges = 0;
  size_t map_surfaces = 0;
};

class OdometryLocator : public ScanLocator {
 public:
  /// Counts of the run so far (read after the pipeline has joined its threads).
  virtual OdometryCounts counts() const = 0;
};

/// Features and registration as `config` says (features.*, odometry.*). The first scan is
/// placed at `T_map_first` (map <- sensor; the identity: the first scan defines the map frame).
std::unique_ptr<OdometryLocator> make_odometry_locator(
    const config::Config& config,
    const Eigen::Isometry3d& T_map_first = Eigen::Isometry3d::Identity());

}  // namespace featsense::slam::odometry
