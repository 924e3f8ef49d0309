#pragma once
/// Where a scan was taken: the front end's stage of the pipeline. Given poses (a surveyed or
/// simulated trajectory) implement it, and so does odometry: the mapping back end takes the
/// answer and never asks how it was found.

#include <Eigen/Geometry>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "featsense/slam/scan.hpp"

namespace featsense::slam {

/// How a pose was found, for the log and the report. Given poses are converged, with no
/// iterations and no fitness.
struct LocateDiagnostics {
  bool converged = true;
  int iterations = 0;
  /// Some direction of motion was not observable in the scan (a corridor, an open field):
  /// the pose there comes from the motion prior.
  bool degenerate = false;
  /// The registration's fitness (mean residual, metres); 0 where nothing was registered.
  double fitness_m = 0.0;
};

/// A scan's place in the map.
struct ScanPlacement {
  uint64_t sequence = 0;
  int64_t stamp_ns = 0;
  /// The sensor's pose at the scan's stamp (map <- sensor, metres).
  Eigen::Isometry3d T_map_sensor = Eigen::Isometry3d::Identity();
  /// The motion over the scan: the sensor's pose when column c was measured, one per column
  /// of the scan. Empty when the scan is taken as rigid (every point at T_map_sensor), as
  /// for poses without times. A point of column c belongs at
  /// column_T_map_sensor[c] * point, and its ray starts at that pose's position.
  std::vector<Eigen::Isometry3d> column_T_map_sensor;
  LocateDiagnostics diagnostics;

  bool deskewed() const { return !column_T_map_sensor.empty(); }
};

/// The sensor's pose for each column of `scan` (ScanPlacement::column_T_map_sensor):
/// `pose_at(t)` at the column's time t (Scan::column_time_offsets_s, seconds after the
/// stamp); `at_stamp` for a column without a valid point, or where `pose_at` has no pose.
std::vector<Eigen::Isometry3d> column_poses(
    const Scan& scan, const Eigen::Isometry3d& at_stamp,
    const std::function<std::optional<Eigen::Isometry3d>(double seconds_after_stamp)>& pose_at);

class ScanLocator {
 public:
  virtual ~ScanLocator() = default;
  /// The scan's place in the map, or nullopt with the reason in `why` when it cannot be
  /// placed (the pipeline skips the scan with a counted warning).
  virtual std::optional<ScanPlacement> locate(const Scan& scan, std::string& why) = 0;
  /// One line for the log and the report, e.g. "given poses (420 stamped poses, deskewed)".
  virtual std::string description() const = 0;
};

}  // namespace featsense::slam
