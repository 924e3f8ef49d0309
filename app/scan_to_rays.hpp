#pragma once
// A scan as TSDF rays in the map frame: each point moved by the sensor pose at its own time
// (deskewing) and its ray starting where the sensor was then.

#include <Eigen/Geometry>

#include <functional>

#include "featsense/slam/scan.hpp"
#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::app {

/// The pose map <- sensor at `seconds_after_stamp` after the scan's stamp.
using PoseAt = std::function<Eigen::Isometry3d(double seconds_after_stamp)>;

/// Every valid point of `scan` in the map frame with the sensor pose at the scan's stamp.
tsdf::RayBatch scan_to_rays(const slam::Scan& scan, const Eigen::Isometry3d& T_map_sensor);

/// The same with per-column poses: `pose_at` is asked once per column (time grows with the
/// column), each point is moved by its own column's pose and its ray starts there.
tsdf::RayBatch deskewed_scan_to_rays(const slam::Scan& scan, const PoseAt& pose_at);

}  // namespace featsense::app
