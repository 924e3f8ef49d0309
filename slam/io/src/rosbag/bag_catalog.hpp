#pragma once
/// What a bag holds (topics, types, message counts), found by a first pass before streaming,
/// because connection records may sit anywhere: inside chunks, or only after them.

#include <cstdint>
#include <istream>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rosbag/bag_record_reader.hpp"

namespace featsense::slam {

/// How a topic's messages are serialized: ROS 1 (unpadded) or CDR (ROS 2).
enum class MessageEncoding { kRos1, kCdr };

/// All connections of one topic (ROS 1), or one topic of a ROS 2 bag or MCAP file.
struct BagTopic {
  std::string name;
  std::string type;  ///< of its first connection, ROS 1 style: "sensor_msgs/PointCloud2"
  MessageEncoding encoding = MessageEncoding::kRos1;
  std::vector<uint32_t> connections;  ///< ids
  uint64_t messages = 0;
};

struct BagCatalog {
  std::vector<BagTopic> topics;  ///< sorted by name
  std::map<uint32_t, BagConnection> connections;
  std::vector<std::string> compressions;  ///< chunk compressions met, in order
  uint64_t chunks = 0;
  /// True where the cheap pass sufficed: a bag closed properly, whose connection and index
  /// records outside the chunks were read without decompressing anything. False where the
  /// chunks had to be walked (an unclosed or damaged bag).
  bool from_index = false;
  /// Warnings of the pass that produced the catalog (the streaming pass meets them again).
  std::vector<std::string> warnings;

  const BagTopic* find(std::string_view topic) const;
};

/// Catalogs a bag: first a walk over the top-level records only (chunk data skipped with
/// seekg); where that walk is incomplete (no index written, damage, connections missing),
/// a full walk that decompresses one chunk at a time and counts the messages. Throws
/// InputError where the stream is not a bag of format 2.0. `max_chunk_bytes` as in
/// BagReadOptions.
BagCatalog catalog_bag(std::istream& stream, const std::string& origin,
                       uint64_t max_chunk_bytes = BagReadOptions().max_chunk_bytes);

/// The `data` of the first std_msgs/String message on `topic` (e.g. Ouster's metadata
/// JSON), or nullopt where the topic has no readable message.
std::optional<std::string> read_first_string_message(std::istream& stream,
                                                     const std::string& origin,
                                                     const BagCatalog& catalog,
                                                     const BagTopic& topic);

}  // namespace featsense::slam
