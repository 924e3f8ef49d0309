#pragma once
/// A recording of serialized ROS messages by topic: a ROS 1 bag, a ROS 2 bag (sqlite3 or
/// MCAP files) or an MCAP file. The scan source streams one topic of it through the decoder
/// of the topic's type, whatever the container.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/scan_source.hpp"
#include "rosbag/bag_catalog.hpp"
#include "rosbag/bag_scan_decoder.hpp"
#include "rosbag/pointcloud2_decoder.hpp"

namespace featsense::slam {

using WarningSink = std::function<void(const std::string&)>;

class MessageLog {
 public:
  virtual ~MessageLog() = default;
  /// The topics, their types, encodings and message counts (known before streaming).
  virtual const BagCatalog& catalog() const = 0;
  /// All messages of `topic` in recording order; damage met on the way goes to `warn`.
  virtual std::unique_ptr<MessageCursor> open(const BagTopic& topic, WarningSink warn) = 0;
  /// One line for humans about the container: files, chunks, compression, index.
  virtual std::string describe() const = 0;
};

/// The decoders the scan source hands messages to. open_rosbag() and the other openers pass
/// the real ones; they are parameters so that the containers stand on their own.
using PacketDecoderFactory = std::function<std::unique_ptr<BagScanDecoder>(
    const BagTopicContext& context, SourceInfo& info)>;

/// The parts of the slam library that the bag sources hand work to: organizing unorganized
/// clouds, sensor presets, and assembling sensor packets into frames.
struct RosbagDependencies {
  CloudOrganizer organize;                ///< organize() of organize.hpp
  SensorLookup sensor_for;                ///< sensor_for() of readers.hpp
  PacketDecoderFactory ouster_packets;    ///< make_ouster_packet_decoder()
  PacketDecoderFactory velodyne_packets;  ///< make_velodyne_scan_decoder()
};

/// The ScanSource of a message log: chooses the topic (options.topic, else the one scan
/// topic), builds its decoder and streams it. `info` comes with format and path set; the
/// rest is filled here. Throws InputError.
std::unique_ptr<ScanSource> open_message_log_source(std::unique_ptr<MessageLog> log,
                                                    SourceInfo info, const SourceOptions& options,
                                                    const RosbagDependencies& dependencies);

/// "name (type, N messages)" for each topic, for `featsense info`.
std::vector<std::string> describe_topics(const BagCatalog& catalog);

}  // namespace featsense::slam
