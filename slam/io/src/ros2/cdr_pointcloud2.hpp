#pragma once
/// sensor_msgs/msg/PointCloud2 of ROS 2 in CDR: std_msgs/Header (builtin_interfaces/Time
/// stamp, string frame_id; no seq), then the same fields as ROS 1 (pointcloud2.hpp), each
/// aligned as CDR wants.

#include "rosbag/pointcloud2.hpp"
#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

/// Parses one CDR message (encapsulation header included); the point data is viewed in
/// place. Throws SerializationError naming the field that runs past the end.
PointCloud2View parse_pointcloud2_cdr(ByteView message);

}  // namespace featsense::slam
