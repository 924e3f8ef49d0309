#include "rosbag/bag_catalog.hpp"

#include <algorithm>

namespace featsense::slam {
namespace {

/// Walks the bag once with the given options, counting nothing but what the reader counts.
struct Walk {
  std::map<uint32_t, BagConnection> connections;
  BagHeaderInfo header;
  BagWalkStats stats;
  std::vector<std::string> warnings;
};

Walk walk(std::istream& stream, const std::string& origin, bool read_chunks,
          uint64_t max_chunk_bytes) {
  Walk result;
  BagReadOptions options;
  options.read_chunks = read_chunks;
  options.max_chunk_bytes = max_chunk_bytes;
  options.wanted = [](const BagMessage&, const BagConnection*) { return false; };
  options.warn = [&result](const std::string& message) { result.warnings.push_back(message); };
  BagRecordReader reader(stream, origin, options);
  while (reader.next()) {
  }
  result.connections = reader.connections();
  result.header = reader.header();
  result.stats = reader.stats();
  return result;
}

/// The cheap walk is complete when the bag was closed properly (index position written),
/// nothing was damaged, and every connection the header announces was found.
bool cheap_walk_suffices(const Walk& cheap) {
  return cheap.warnings.empty() && cheap.stats.reached_end && cheap.header.present &&
         cheap.header.index_pos > 0 && !cheap.connections.empty() &&
         cheap.connections.size() >= cheap.header.conn_count &&
         cheap.stats.chunks == cheap.header.chunk_count;
}

}  // namespace

const BagTopic* BagCatalog::find(std::string_view topic) const {
  for (const BagTopic& t : topics) {
    if (t.name == topic) return &t;
  }
  return nullptr;
}

BagCatalog catalog_bag(std::istream& stream, const std::string& origin, uint64_t max_chunk_bytes) {
  BagCatalog catalog;
  Walk pass = walk(stream, origin, /*read_chunks=*/false, max_chunk_bytes);
  std::map<uint32_t, uint64_t> counts;
  if (cheap_walk_suffices(pass)) {
    catalog.from_index = true;
    counts = pass.stats.index_counts;
    // Messages outside chunks are not indexed by chunk; the walk counted them itself.
    for (const auto& [id, count] : pass.stats.message_counts) counts[id] += count;
  } else {
    pass = walk(stream, origin, /*read_chunks=*/true, max_chunk_bytes);
    counts = pass.stats.message_counts;
  }
  catalog.connections = pass.connections;
  catalog.compressions = pass.stats.compressions;
  catalog.chunks = pass.stats.chunks;
  catalog.warnings = pass.warnings;

  std::map<std::string, BagTopic> topics;
  for (const auto& [id, connection] : catalog.connections) {
    BagTopic& topic = topics[connection.topic];
    if (topic.connections.empty()) {
      topic.name = connection.topic;
      topic.type = connection.type;
    }
    topic.connections.push_back(id);
    const auto count = counts.find(id);
    if (count != counts.end()) topic.messages += count->second;
  }
  for (auto& [name, topic] : topics) catalog.topics.push_back(std::move(topic));
  return catalog;
}

std::optional<std::string> read_first_string_message(std::istream& stream,
                                                     const std::string& origin,
                                                     const BagCatalog& catalog,
                                                     const BagTopic& topic) {
  BagReadOptions options;
  options.wanted = [&topic](const BagMessage&, const BagConnection* connection) {
    return connection != nullptr && connection->topic == topic.name;
  };
  BagRecordReader reader(stream, origin, options);
  for (const auto& [id, connection] : catalog.connections) reader.add_connection(connection);
  while (const std::optional<BagMessage> message = reader.next()) {
    try {
      RosDeserializer in(message->data);
      return in.string("std_msgs/String data");
    } catch (const SerializationError&) {
      continue;  // a damaged copy; a later message may be whole
    }
  }
  return std::nullopt;
}

}  // namespace featsense::slam
