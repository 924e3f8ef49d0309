#pragma once
/// The interface between the bag source, which streams the messages of one topic, and the
/// decoder of that topic's message type.

#include <functional>
#include <istream>
#include <optional>
#include <string>

#include "featsense/config/sensor_model.hpp"
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

/// What a decoder factory may look at while the bag is being opened.
struct BagTopicContext {
  std::istream& stream;  ///< the bag, for a look at the first messages (any position)
  const std::string& origin;
  const BagCatalog& catalog;
  const BagTopic& topic;  ///< the topic to decode
  const SourceOptions& options;
};

/// The sensor model for a recording without metadata: sensor_for() of readers.hpp.
using SensorLookup =
    std::function<config::SensorModel(const SourceOptions& options, const std::string& fallback)>;

/// Turns the messages of one topic, in file order, into scans.
class BagScanDecoder {
 public:
  virtual ~BagScanDecoder() = default;
  /// One message of the topic; a scan where one is complete. A message that cannot be
  /// decoded is reported and yields nothing; decoders do not throw for bad messages.
  virtual std::optional<Scan> decode(const BagMessage& message, const DecodeReport& report) = 0;
  /// At the end of the bag: a scan still being assembled, if any.
  virtual std::optional<Scan> finish(const DecodeReport& /*report*/) { return std::nullopt; }
};

}  // namespace featsense::slam
