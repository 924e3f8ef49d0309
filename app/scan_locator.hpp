#pragma once
// Where a scan was taken: the front end's stage of the pipeline. Today the poses are given
// (a ground-truth or surveyed trajectory); the odometry front end implements the same
// interface and takes this stage's place.

#include <Eigen/Geometry>

#include <memory>
#include <optional>
#include <string>

#include "featsense/slam/scan.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::app {

/// A scan placed in the map: its rays in the map frame and the sensor pose at its stamp.
struct LocatedScan {
  uint64_t sequence = 0;
  int64_t stamp_ns = 0;
  Eigen::Isometry3d T_map_sensor = Eigen::Isometry3d::Identity();
  tsdf::RayBatch rays;
};

class ScanLocator {
 public:
  virtual ~ScanLocator() = default;
  /// The scan placed in the map, or nullopt with the reason in `why` when it cannot be (the
  /// pipeline skips it with a counted warning).
  virtual std::optional<LocatedScan> locate(const slam::Scan& scan, std::string& why) = 0;
  /// One line for the log and the report, e.g. "given poses (TUM, 420 poses, deskewed)".
  virtual std::string description() const = 0;
};

/// Poses from `trajectory`: with stamps, interpolated to each scan's time (and, when
/// `deskew`, to each column's time, so every point is placed where the sensor was when it
/// was measured); without stamps (KITTI), pose i belongs to scan i of the recording.
std::unique_ptr<ScanLocator> make_given_pose_locator(slam::Trajectory trajectory, bool deskew);

}  // namespace featsense::app
