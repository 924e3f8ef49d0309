#pragma once
/// velodyne_msgs/VelodyneScan (ROS 1) and velodyne_msgs/msg/VelodyneScan (ROS 2): a
/// std_msgs/Header, then VelodynePacket[] packets, each a time stamp and uint8[1206] data
/// (a fixed array: no length before it).

#include <cstdint>
#include <string>
#include <vector>

#include "rosbag/bag_catalog.hpp"
#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

struct VelodynePacketView {
  int64_t stamp_ns = 0;
  ByteView data;  ///< kVelodynePacketBytes, viewed in the message
};

struct VelodyneScanView {
  int64_t stamp_ns = 0;
  std::string frame_id;
  std::vector<VelodynePacketView> packets;
};

/// Parses one message. Throws SerializationError naming the field that runs past the end.
VelodyneScanView parse_velodyne_scan(ByteView message, MessageEncoding encoding);

}  // namespace featsense::slam
