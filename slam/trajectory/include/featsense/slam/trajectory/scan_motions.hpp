#pragma once
/// The motion of the sensor within each scan as the map was first made with it, kept so that
/// the scans can be placed again with corrected poses (the loop closure's second pass) and
/// deskewed exactly as the first time.
///
/// Why not interpolate the corrected poses between the stamps instead: the odometry fits each
/// scan's pose at its stamp together with a motion over the sweep (the last scan's velocity).
/// Where the sensor turns faster and faster (a car entering a corner) the fitted pose at the
/// stamp leads or lags the truth by about half of what the sweep's points would be off without
/// it, while the sweep as placed fits the map. Interpolating between two such stamps moves the
/// whole sweep by that offset (0.6 deg in the town's corners); the motion kept here places it
/// as it was fitted.

#include <Eigen/Geometry>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>

#include "featsense/slam/scan.hpp"
#include "featsense/slam/scan_locator.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

/// One scan's motion at constant velocity: the sensor at the stamp <- the sensor span_s later.
struct ScanMotion {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  double span_s = 0.0;
};

/// The scans' motions by stamp.
class ScanMotions {
 public:
  /// Keeps the motion of a placed scan from its column poses (the column measured last, and
  /// its time); nothing where the placement is not deskewed.
  void add(const Scan& scan, const ScanPlacement& placement);
  std::optional<ScanMotion> at(int64_t stamp_ns) const;
  size_t size() const { return motions_.size(); }

 private:
  std::map<int64_t, ScanMotion> motions_;
};

/// Poses at the scans' stamps from `trajectory` (interpolated), and each scan's columns moved
/// from there by its kept motion; a scan without one is deskewed by interpolating the
/// trajectory (as make_given_pose_locator).
std::unique_ptr<ScanLocator> make_replay_locator(Trajectory trajectory, ScanMotions motions);

}  // namespace featsense::slam
