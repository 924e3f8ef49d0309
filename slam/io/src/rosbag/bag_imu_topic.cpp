#include "rosbag/bag_imu_topic.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

#include "featsense/config/config_error.hpp"
#include "rosbag/bag_topic_choice.hpp"
#include "rosbag/imu_message.hpp"

namespace featsense::slam {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

bool is_imu_message_type(const BagTopic& topic) {
  return ros1_style_type(topic.type) == "sensor_msgs/Imu";
}

/// "/os_node0/lidar_packets" -> "/os_node0".
std::string name_space(const std::string& topic) {
  const size_t slash = topic.rfind('/');
  return slash == std::string::npos ? std::string() : topic.substr(0, slash);
}

std::string names(const std::vector<const BagTopic*>& topics) {
  std::string out;
  for (const BagTopic* topic : topics) out += (out.empty() ? "" : ", ") + topic->name;
  return out;
}

/// The sensor_msgs/Imu decoder with the configured rotation, and its description.
BagImuTopic imu_message_topic(const BagTopic& topic, const SourceOptions& options) {
  BagImuTopic chosen;
  chosen.topic = &topic;
  chosen.decoder = make_imu_message_decoder(
      topic.encoding, rotation_from_roll_pitch_yaw_deg(options.imu_rotation_deg));
  const auto& rpy = options.imu_rotation_deg;
  const bool identity = rpy[0] == 0.0 && rpy[1] == 0.0 && rpy[2] == 0.0;
  chosen.description =
      "topic " + topic.name + " (sensor_msgs/Imu), " +
      (identity ? std::string("the IMU assumed aligned with the LiDAR (set sensor.imu_rotation "
                              "where it is not)")
                : "turned into the sensor frame by sensor.imu_rotation");
  return chosen;
}

BagImuTopic ouster_packet_topic(const BagTopic& topic, const BagScanDecoder& scan_decoder,
                                const std::string& origin) {
  BagImuTopic chosen;
  chosen.decoder = scan_decoder.packet_imu_decoder();
  if (!chosen.decoder) {
    throw InputError(origin + ": the Ouster IMU packets on " + topic.name +
                     " can only be read beside Ouster lidar packets (their metadata)");
  }
  chosen.topic = &topic;
  chosen.description = "topic " + topic.name +
                       " (Ouster IMU packets), turned into the sensor frame by the metadata's "
                       "imu_to_sensor_transform";
  return chosen;
}

}  // namespace

Eigen::Matrix3d rotation_from_roll_pitch_yaw_deg(const std::array<double, 3>& roll_pitch_yaw) {
  return (Eigen::AngleAxisd(roll_pitch_yaw[2] * kDegToRad, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(roll_pitch_yaw[1] * kDegToRad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_pitch_yaw[0] * kDegToRad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

BagImuTopic choose_imu_topic(const BagCatalog& catalog, const BagTopic& scans,
                             const BagScanDecoder& scan_decoder, const SourceOptions& options,
                             const std::string& origin) {
  if (!options.imu) return {};
  if (options.imu_topic) {
    const BagTopic* topic = catalog.find(*options.imu_topic);
    if (topic == nullptr) {
      std::vector<std::string> all;
      for (const BagTopic& t : catalog.topics) all.push_back(t.name);
      std::string message =
          origin + ": no topic '" + *options.imu_topic + "' (sensor.imu_topic) in the bag";
      const std::string hint = config::closest_match(*options.imu_topic, all);
      if (!hint.empty()) message += " (did you mean '" + hint + "'?)";
      throw InputError(message);
    }
    if (classify_topic(*topic) == BagTopicKind::kOusterImuPackets) {
      return ouster_packet_topic(*topic, scan_decoder, origin);
    }
    if (is_imu_message_type(*topic)) return imu_message_topic(*topic, options);
    throw InputError(origin + ": topic '" + topic->name + "' (sensor.imu_topic) holds " +
                     topic->type + ", not sensor_msgs/Imu or Ouster IMU packets");
  }

  if (classify_topic(scans) == BagTopicKind::kOusterLidarPackets) {
    std::vector<const BagTopic*> packets;
    for (const BagTopic& topic : catalog.topics) {
      if (classify_topic(topic) != BagTopicKind::kOusterImuPackets) continue;
      // The driver's own IMU topic wins over those of other sensors in the bag.
      if (name_space(topic.name) == name_space(scans.name)) {
        return ouster_packet_topic(topic, scan_decoder, origin);
      }
      packets.push_back(&topic);
    }
    if (packets.size() == 1) return ouster_packet_topic(*packets[0], scan_decoder, origin);
    if (packets.size() > 1) {
      BagImuTopic none;
      none.description = "none read: several Ouster IMU packet topics (" + names(packets) +
                         "); choose one with sensor.imu_topic";
      return none;
    }
  }

  std::vector<const BagTopic*> messages;
  for (const BagTopic& topic : catalog.topics) {
    if (is_imu_message_type(topic) && topic.messages > 0) messages.push_back(&topic);
  }
  if (messages.size() == 1) return imu_message_topic(*messages[0], options);
  BagImuTopic none;
  if (messages.size() > 1) {
    none.description = "none read: several sensor_msgs/Imu topics (" + names(messages) +
                       "); choose one with sensor.imu_topic";
  }
  return none;
}

}  // namespace featsense::slam
