#pragma once
/// The front end's stage with given poses: a trajectory file instead of odometry.

#include <memory>

#include "featsense/slam/scan_locator.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

/// Poses from `trajectory`. With stamps (TUM) they are interpolated to each scan's stamp
/// and, when `deskew` and the scan has per-point times, to each column's time, so that every
/// point is placed where the sensor was when it was measured. Without stamps (KITTI) pose i
/// belongs to scan i of the recording and the scan is taken as rigid.
std::unique_ptr<ScanLocator> make_given_pose_locator(Trajectory trajectory, bool deskew);

}  // namespace featsense::slam
