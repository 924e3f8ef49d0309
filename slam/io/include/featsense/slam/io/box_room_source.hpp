#pragma once
/// A built-in analytic recording: a spinning LiDAR moving in a straight line through an
/// empty box-shaped room. Every return is an exact ray-box intersection, so it serves as the
/// example input of `featsense info` when no recording is given and as an exact reference
/// for tests. (The full simulator with scenes and noise is `featsense simulate`.)

#include <Eigen/Geometry>

#include <memory>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {

struct BoxRoomSettings {
  config::SensorModel sensor;                                 ///< default: the os1-128 preset
  Eigen::Vector3d room_min_m = Eigen::Vector3d(-10, -10, 0);  ///< room corners, map frame
  Eigen::Vector3d room_max_m = Eigen::Vector3d(10, 10, 4);
  Eigen::Vector3d start_m = Eigen::Vector3d(-2, 0, 1.5);    ///< sensor position at t = 0
  Eigen::Vector3d velocity_mps = Eigen::Vector3d(1, 0, 0);  ///< constant, sensor not rotating
  int frames = 10;
  int64_t start_stamp_ns = 1'700'000'000'000'000'000;
};

/// The default settings with the os1-128 preset.
BoxRoomSettings default_box_room();

/// The sensor pose (map <- sensor) at `seconds` after the first frame's stamp.
Eigen::Isometry3d box_room_pose(const BoxRoomSettings& settings, double seconds);

/// Scans of the room: each column is fired at its own time along the motion, so the scan
/// is distorted as a spinning sensor's is, and time_offset_s says when each point was taken.
std::unique_ptr<ScanSource> make_box_room_source(const BoxRoomSettings& settings);

}  // namespace featsense::slam
