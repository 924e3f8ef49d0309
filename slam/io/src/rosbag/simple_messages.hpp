#pragma once
/// Messages of one field, in either encoding (ROS 1 or CDR): ouster_ros/PacketMsg and
/// ouster_sensor_msgs/msg/PacketMsg (uint8[] buf) and std_msgs/String (string data).

#include <optional>
#include <string>

#include "rosbag/bag_catalog.hpp"
#include "rosbag/message_log.hpp"
#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

/// The bytes of a uint8[] that is the message's only field, viewed in place. Throws
/// SerializationError.
ByteView byte_array_message(ByteView message, MessageEncoding encoding);

/// The text of a std_msgs/String. Throws SerializationError.
std::string string_message(ByteView message, MessageEncoding encoding);

/// The text of the first readable std_msgs/String message on `topic` (e.g. Ouster's
/// metadata JSON), or nullopt where it has none.
std::optional<std::string> first_string_message(const TopicOpener& open_topic,
                                                const BagTopic& topic);

}  // namespace featsense::slam
