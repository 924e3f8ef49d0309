// Fuzzes the ROS bag reader: the catalog pass, the topic choice, the streaming record reader
// and the PointCloud2 decoder, over arbitrary bytes. Anything but InputError escaping, a
// sanitizer report, or a hang is a bug.

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "featsense/slam/scan_source.hpp"
#include "rosbag/bag_catalog.hpp"
#include "rosbag/bag_record_reader.hpp"
#include "rosbag/bag_topic_choice.hpp"
#include "rosbag/pointcloud2_decoder.hpp"
#include "rosbag/ros_serialization.hpp"

namespace {

using namespace featsense::slam;

/// Smaller than the reader's 1 GiB so that a lying chunk size costs milliseconds, not the
/// fuzzer's time limit; the bound is the same code path.
constexpr uint64_t kFuzzMaxChunkBytes = uint64_t{16} << 20;

/// A 16-beam model for the unorganized clouds, whose organizer is not part of this target.
featsense::config::SensorModel fuzz_sensor() {
  featsense::config::SensorModel sensor;
  sensor.name = "fuzz";
  sensor.beams = 16;
  sensor.columns = 64;
  sensor.elevation_rad.assign(16, 0.0);
  sensor.azimuth_offset_rad.assign(16, 0.0);
  return sensor;
}

void read_bag(const std::string& bytes) {
  std::istringstream stream(bytes);
  const BagCatalog catalog = catalog_bag(stream, "fuzz.bag", kFuzzMaxChunkBytes);
  try {
    const BagTopic& topic = choose_scan_topic(catalog, std::nullopt, "fuzz.bag");
    if (classify_topic(topic) == BagTopicKind::kOusterLidarPackets) {
      if (const BagTopic* metadata = metadata_topic_for(catalog, topic)) {
        read_first_string_message(stream, "fuzz.bag", catalog, *metadata);
      }
    }
  } catch (const InputError&) {
  }

  BagReadOptions options;
  options.max_chunk_bytes = kFuzzMaxChunkBytes;
  BagRecordReader reader(stream, "fuzz.bag", options);
  for (const auto& [id, connection] : catalog.connections) reader.add_connection(connection);
  // Every message is tried as a PointCloud2, whatever its connection says, to reach the
  // decoder with as many inputs as possible.
  PointCloud2Decoder decoder(
      fuzz_sensor(), [](const PointCloud& cloud, const featsense::config::SensorModel& sensor) {
        Scan scan = Scan::allocate(sensor.beams, sensor.columns);
        scan.stamp_ns = cloud.stamp_ns;
        return scan;
      });
  DecodeReport report;
  report.warn = [](const std::string&) {};
  report.skip_frame = [](const std::string&) {};
  while (const std::optional<BagMessage> message = reader.next()) {
    decoder.decode(*message, report);
    try {
      RosDeserializer in(message->data);
      in.byte_array("buf");  // the layout of both PacketMsg and std_msgs/String
    } catch (const SerializationError&) {
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    read_bag(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const InputError&) {
    // Not a bag at all: the expected answer to most inputs.
  }
  return 0;
}
