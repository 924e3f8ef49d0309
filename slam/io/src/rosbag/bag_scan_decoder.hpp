#pragma once
/// The interface between the bag source, which streams the messages of one topic, and the
/// decoder of that topic's message type (scans, or the IMU's samples).

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/imu_sample.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/scan.hpp"
#include "featsense/slam/scan_source.hpp"
#include "rosbag/bag_catalog.hpp"
#include "rosbag/bag_record_reader.hpp"

namespace featsense::slam {

/// Where a decoder reports what it skipped; the source counts it in its ReadStats.
struct DecodeReport {
  std::function<void(const std::string&)> warn;        ///< a counted warning
  std::function<void(const std::string&)> skip_frame;  ///< a skipped frame, with the reason
};

/// The messages of one topic in recording order, one at a time.
class MessageCursor {
 public:
  virtual ~MessageCursor() = default;
  /// The next message, or nullopt at the end; its data stays valid until the next call.
  virtual std::optional<BagMessage> next() = 0;
};

/// A fresh pass over the messages of a topic, for a look at the first ones; damage met on
/// the way is not reported (the streaming pass reports it).
using TopicOpener = std::function<std::unique_ptr<MessageCursor>(const BagTopic& topic)>;

/// What a decoder factory may look at while the bag is being opened.
struct BagTopicContext {
  TopicOpener open_topic;
  const std::string& origin;
  const BagCatalog& catalog;
  const BagTopic& topic;  ///< the topic to decode
  const SourceOptions& options;
};

/// The sensor model for a recording without metadata: sensor_for() of readers.hpp.
using SensorLookup =
    std::function<config::SensorModel(const SourceOptions& options, const std::string& fallback)>;

/// Turns one message of an IMU topic (sensor_msgs/Imu, Ouster's IMU packets) into a sample.
class ImuMessageDecoder {
 public:
  virtual ~ImuMessageDecoder() = default;
  /// The sample of one message, in the sensor frame and the scans' clock; a message that
  /// cannot be decoded is reported and yields nothing.
  virtual std::optional<ImuSample> decode(const BagMessage& message,
                                          const DecodeReport& report) = 0;
};

/// Turns the messages of one topic, in file order, into scans.
class BagScanDecoder {
 public:
  virtual ~BagScanDecoder() = default;
  /// One message of the topic; a scan where one is complete. A message that cannot be
  /// decoded is reported and yields nothing; decoders do not throw for bad messages.
  virtual std::optional<Scan> decode(const BagMessage& message, const DecodeReport& report) = 0;
  /// At the end of the bag: a scan still being assembled, if any.
  virtual std::optional<Scan> finish(const DecodeReport& /*report*/) { return std::nullopt; }
  /// A further scan completed by the last message or finish() (a message of many packets
  /// may complete several); asked for until it returns nullopt.
  virtual std::optional<Scan> take_pending() { return std::nullopt; }
  /// The decoder of the IMU packets recorded beside these scans' packets, which need the same
  /// sensor description (Ouster's metadata); nullptr for other message types.
  virtual std::unique_ptr<ImuMessageDecoder> packet_imu_decoder() const { return nullptr; }
};

}  // namespace featsense::slam
