#include "rosbag/bag_topic_choice.hpp"

#include <vector>

#include "featsense/config/config_error.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {
namespace {

/// "/os_node0/lidar_packets" -> "lidar_packets".
std::string last_part(const std::string& topic) {
  const size_t slash = topic.rfind('/');
  return slash == std::string::npos ? topic : topic.substr(slash + 1);
}

/// "/os_node0/lidar_packets" -> "/os_node0".
std::string name_space(const std::string& topic) {
  const size_t slash = topic.rfind('/');
  return slash == std::string::npos ? std::string() : topic.substr(0, slash);
}

std::string describe(const BagTopic& topic) {
  return topic.name + " (" + topic.type + ", " + std::to_string(topic.messages) + " messages)";
}

std::string list_topics(const std::vector<const BagTopic*>& topics) {
  std::string out;
  for (const BagTopic* topic : topics) out += (out.empty() ? "" : ", ") + describe(*topic);
  return out;
}

std::string all_topics(const BagCatalog& catalog) {
  std::vector<const BagTopic*> topics;
  for (const BagTopic& topic : catalog.topics) topics.push_back(&topic);
  return topics.empty() ? std::string("none") : list_topics(topics);
}

constexpr const char* kSupported =
    "sensor_msgs/PointCloud2, velodyne_msgs/VelodyneScan, or ouster_ros/PacketMsg lidar "
    "packets with their metadata";

}  // namespace

std::string ros1_style_type(const std::string& type) {
  const size_t at = type.find("/msg/");
  if (at == std::string::npos) return type;
  return type.substr(0, at) + "/" + type.substr(at + 5);
}

BagTopicKind classify_topic(const BagTopic& topic) {
  const std::string last = last_part(topic.name);
  if (topic.type == "sensor_msgs/PointCloud2") return BagTopicKind::kPointCloud2;
  if (topic.type == "ouster_ros/PacketMsg" || topic.type == "ouster_sensor_msgs/PacketMsg") {
    return last.find("imu") != std::string::npos ? BagTopicKind::kOusterImuPackets
                                                 : BagTopicKind::kOusterLidarPackets;
  }
  if (topic.type == "velodyne_msgs/VelodyneScan") return BagTopicKind::kVelodyneScan;
  if (topic.type == "std_msgs/String" && last.find("metadata") != std::string::npos) {
    return BagTopicKind::kOusterMetadata;
  }
  return BagTopicKind::kOther;
}

bool is_scan_kind(BagTopicKind kind) {
  return kind == BagTopicKind::kPointCloud2 || kind == BagTopicKind::kOusterLidarPackets ||
         kind == BagTopicKind::kVelodyneScan;
}

const BagTopic& choose_scan_topic(const BagCatalog& catalog,
                                  const std::optional<std::string>& wanted,
                                  const std::string& origin) {
  if (catalog.topics.empty()) {
    std::string message = origin + ": no readable connection records, so no topics";
    if (!catalog.warnings.empty()) message += " (first problem: " + catalog.warnings[0] + ")";
    throw InputError(message);
  }
  if (wanted) {
    const BagTopic* topic = catalog.find(*wanted);
    if (topic == nullptr) {
      std::vector<std::string> names;
      for (const BagTopic& t : catalog.topics) names.push_back(t.name);
      std::string message = origin + ": no topic '" + *wanted + "' in the bag";
      const std::string hint = config::closest_match(*wanted, names);
      if (!hint.empty()) message += " (did you mean '" + hint + "'?)";
      throw InputError(message + "; its topics: " + all_topics(catalog));
    }
    const BagTopicKind kind = classify_topic(*topic);
    if (kind == BagTopicKind::kOusterImuPackets) {
      throw InputError(
          origin + ": topic '" + *wanted +
          "' holds Ouster IMU packets, not lidar data; its topics: " + all_topics(catalog));
    }
    if (!is_scan_kind(kind)) {
      throw InputError(origin + ": topic '" + *wanted + "' holds " + topic->type +
                       ", which is not a scan type (supported: " + kSupported + ")");
    }
    return *topic;
  }

  std::vector<const BagTopic*> candidates;
  std::vector<const BagTopic*> with_messages;
  for (const BagTopic& topic : catalog.topics) {
    if (!is_scan_kind(classify_topic(topic))) continue;
    candidates.push_back(&topic);
    if (topic.messages > 0) with_messages.push_back(&topic);
  }
  if (!with_messages.empty()) candidates = with_messages;
  if (candidates.empty()) {
    throw InputError(origin + ": no topic holds scans (supported: " + kSupported +
                     "); its topics: " + all_topics(catalog));
  }
  if (candidates.size() > 1) {
    throw InputError(origin + ": several topics hold scans: " + list_topics(candidates) +
                     "; choose one with the topic option (--topic " + candidates[0]->name + ")");
  }
  return *candidates[0];
}

const BagTopic* metadata_topic_for(const BagCatalog& catalog, const BagTopic& packets) {
  std::vector<const BagTopic*> metadata;
  for (const BagTopic& topic : catalog.topics) {
    if (classify_topic(topic) != BagTopicKind::kOusterMetadata) continue;
    if (name_space(topic.name) == name_space(packets.name)) return &topic;
    metadata.push_back(&topic);
  }
  return metadata.size() == 1 ? metadata[0] : nullptr;
}

}  // namespace featsense::slam
