#include "rosbag/rosbag_ouster_packets.hpp"

#include <fstream>
#include <sstream>
#include <string>
#include <utility>

#include "featsense/slam/io/ouster_frame_assembler.hpp"
#include "featsense/slam/io/ouster_metadata.hpp"
#include "ouster/ouster_imu_packet.hpp"
#include "rosbag/bag_catalog.hpp"
#include "rosbag/bag_scan_decoder.hpp"
#include "rosbag/bag_topic_choice.hpp"
#include "rosbag/ros_serialization.hpp"
#include "rosbag/simple_messages.hpp"

namespace featsense::slam {
namespace {

std::string read_text_file(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open the Ouster metadata JSON");
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

/// The payload of each PacketMsg of an IMU packet topic, decoded as the pcap reader does.
class OusterImuPacketDecoder final : public ImuMessageDecoder {
 public:
  OusterImuPacketDecoder(const OusterMetadata& metadata, MessageEncoding encoding)
      : imu_to_sensor_(detail::ouster_imu_to_sensor_rotation(metadata)), encoding_(encoding) {}

  std::optional<ImuSample> decode(const BagMessage& message, const DecodeReport& report) override {
    ByteView payload;
    try {
      payload = byte_array_message(message.data, encoding_);
    } catch (const SerializationError& e) {
      report.warn("IMU packet at offset " + std::to_string(message.offset) + ": " + e.what());
      return std::nullopt;
    }
    std::optional<ImuSample> sample =
        detail::decode_ouster_imu_packet(payload.data, payload.size, imu_to_sensor_);
    if (!sample) {
      report.warn("IMU packet at offset " + std::to_string(message.offset) +
                  (payload.size == detail::kOusterImuPacketBytes
                       ? std::string(" holds a non-finite value")
                       : " has " + std::to_string(payload.size) + " bytes, not " +
                             std::to_string(detail::kOusterImuPacketBytes)) +
                  "; ignored");
    }
    return sample;
  }

 private:
  Eigen::Matrix3d imu_to_sensor_;
  MessageEncoding encoding_;
};

/// Feeds the payload of each PacketMsg to the frame assembler; scans come out as frames
/// complete.
class OusterPacketDecoder final : public BagScanDecoder {
 public:
  OusterPacketDecoder(OusterMetadata metadata, MessageEncoding encoding)
      : packet_size_(metadata.packet_size()),
        assembler_(std::move(metadata)),
        encoding_(encoding) {}

  std::optional<Scan> decode(const BagMessage& message, const DecodeReport& report) override {
    ByteView payload;
    try {
      payload = byte_array_message(message.data, encoding_);
    } catch (const SerializationError& e) {
      report.warn("packet at offset " + std::to_string(message.offset) + ": " + e.what());
      return std::nullopt;
    }
    if (payload.size != packet_size_) {
      report.warn("packet at offset " + std::to_string(message.offset) + " has " +
                  std::to_string(payload.size) + " bytes, not the lidar packet size " +
                  std::to_string(packet_size_) + " of the metadata; ignored");
      return std::nullopt;
    }
    return hand_out(assembler_.add_packet(payload.data, payload.size), report);
  }

  std::optional<Scan> finish(const DecodeReport& report) override {
    std::optional<Scan> scan = hand_out(assembler_.flush(), report);
    if (assembler_.rejected_packets() > 0) {
      report.warn(std::to_string(assembler_.rejected_packets()) +
                  " lidar packets rejected by the decoder");
    }
    return scan;
  }

  std::unique_ptr<ImuMessageDecoder> packet_imu_decoder() const override {
    // The IMU topic is written by the same driver as the lidar topic, in the same encoding.
    return std::make_unique<OusterImuPacketDecoder>(assembler_.metadata(), encoding_);
  }

 private:
  /// Numbers the scans in order and warns about frames that lacked columns.
  std::optional<Scan> hand_out(std::optional<Scan> scan, const DecodeReport& report) {
    if (!scan) return scan;
    scan->sequence = next_sequence_++;
    if (assembler_.incomplete_frames() > incomplete_reported_) {
      incomplete_reported_ = assembler_.incomplete_frames();
      report.warn("frame " + std::to_string(scan->sequence) +
                  " is incomplete (packets missing); its missing columns are invalid");
    }
    return scan;
  }

  size_t packet_size_;
  OusterFrameAssembler assembler_;
  MessageEncoding encoding_;
  uint64_t next_sequence_ = 0;
  size_t incomplete_reported_ = 0;
};

std::vector<std::string> fields_of(OusterProfile profile) {
  if (profile == OusterProfile::kRng15Rfl8Nir8) {
    return {"x", "y", "z", "range", "t", "reflectivity", "nir"};
  }
  return {"x", "y", "z", "range", "t", "reflectivity", "signal", "nir"};
}

}  // namespace

std::unique_ptr<BagScanDecoder> make_ouster_packet_decoder(const BagTopicContext& context,
                                                           SourceInfo& info) {
  std::string json;
  std::string json_origin;
  if (context.options.meta_path) {
    json_origin = *context.options.meta_path;
    json = read_text_file(json_origin);
  } else if (const BagTopic* topic = metadata_topic_for(context.catalog, context.topic)) {
    std::optional<std::string> text = first_string_message(context.open_topic, *topic);
    if (!text) {
      throw InputError(context.origin + ": the metadata topic " + topic->name +
                       " holds no readable message; pass the sensor's metadata JSON (--meta)");
    }
    json = std::move(*text);
    json_origin = context.origin + " topic " + topic->name;
  } else {
    throw InputError(context.origin + ": the Ouster packets on " + context.topic.name +
                     " need the sensor's metadata JSON, and the bag has no metadata topic; "
                     "pass it with --meta");
  }
  OusterMetadata metadata = parse_ouster_metadata(json, json_origin);
  info.sensor = metadata.sensor_model();
  info.sensor_from_metadata = true;
  info.fields = fields_of(metadata.profile);
  info.detail = metadata.prod_line + " " + metadata.lidar_mode + ", profile " +
                to_string(metadata.profile) + ", metadata from " + json_origin;
  info.times = "per column, from the lidar packets' timestamps";
  return std::make_unique<OusterPacketDecoder>(std::move(metadata), context.topic.encoding);
}

}  // namespace featsense::slam
