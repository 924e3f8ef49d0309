#pragma once
/// Which topic of a bag holds the scans, and which holds the Ouster metadata.

#include <optional>
#include <string>

#include "rosbag/bag_catalog.hpp"

namespace featsense::slam {

enum class BagTopicKind {
  kPointCloud2,         ///< sensor_msgs/PointCloud2
  kOusterLidarPackets,  ///< ouster_ros/PacketMsg (or ouster_sensor_msgs/) not named "imu"
  kOusterImuPackets,    ///< the same type on a topic whose last name part holds "imu"
  kOusterMetadata,      ///< std_msgs/String on a topic whose last name part holds "metadata"
  kVelodyneScan,        ///< velodyne_msgs/VelodyneScan (raw Velodyne packets)
  kOther,
};

/// A ROS 2 type name in the ROS 1 style the topic kinds are told by:
/// "sensor_msgs/msg/PointCloud2" -> "sensor_msgs/PointCloud2"; others stay as they are.
std::string ros1_style_type(const std::string& type);

/// Both Ouster packet topics have the same type; the driver names them `.../lidar_packets`
/// and `.../imu_packets`, so the topic name tells them apart.
BagTopicKind classify_topic(const BagTopic& topic);

/// True for the kinds that yield scans (PointCloud2, Ouster lidar packets, Velodyne scans).
bool is_scan_kind(BagTopicKind kind);

/// The topic to read: `wanted` where given (which must exist and hold scans), else the one
/// scan topic of the bag (topics with messages preferred). Throws InputError naming the
/// bag's topics when there is none, several, or `wanted` is unknown (with a did-you-mean).
const BagTopic& choose_scan_topic(const BagCatalog& catalog,
                                  const std::optional<std::string>& wanted,
                                  const std::string& origin);

/// The metadata topic that belongs to a packet topic: the metadata topic in the same
/// namespace (`/os_node0/lidar_packets` -> `/os_node0/metadata`), else the only one there
/// is; nullptr where none or several unrelated ones exist.
const BagTopic* metadata_topic_for(const BagCatalog& catalog, const BagTopic& packets);

}  // namespace featsense::slam
