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
#include <vector>

#include "featsense/slam/scan.hpp"
#include "featsense/slam/scan_locator.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

/// One scan's motion as placed: the sensor at the stamp <- the sensor at a few instants over
/// the sweep (the stamp among them), interpolated between them. Nine instants follow a turn
/// that speeds up at 130 deg/s^2 within 0.004 deg over a 0.1 s sweep; in single precision
/// (about 300 bytes a scan) because the motion over one sweep is small.
class ScanMotion {
 public:
  /// The knots from a placement's column poses; empty where it is not deskewed or its scan
  /// tells no times.
  static ScanMotion of(const Scan& scan, const ScanPlacement& placement);

  bool empty() const { return times_s_.empty(); }
  /// The sensor at the stamp <- the sensor t seconds after it: between the knots as
  /// interpolate_pose, beyond them the nearest two continued.
  Eigen::Isometry3d at(double t_s) const;

 private:
  std::vector<float> times_s_;
  std::vector<Eigen::Quaternionf> rotations_;
  std::vector<Eigen::Vector3f> translations_;
};

/// The scans' motions by stamp.
class ScanMotions {
 public:
  /// Keeps the motion of a placed scan (ScanMotion::of); nothing where it is empty.
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
