#include "velodyne/velodyne_bag_packets.hpp"

#include <vector>

#include "featsense/slam/io/readers.hpp"
#include "velodyne/velodyne_scan_message.hpp"
#include "velodyne/velodyne_setup.hpp"

namespace featsense::slam {
namespace {

class VelodyneScanDecoder final : public BagScanDecoder {
 public:
  VelodyneScanDecoder(const VelodyneSetup& setup, MessageEncoding encoding)
      : assembler_(make_velodyne_assembler(setup)), encoding_(encoding) {}

  std::optional<Scan> decode(const BagMessage& message, const DecodeReport& report) override {
    VelodyneScanView scan;
    try {
      scan = parse_velodyne_scan(message.data, encoding_);
    } catch (const SerializationError& e) {
      report.skip_frame("VelodyneScan message at " + std::to_string(message.offset) + ": " +
                        e.what());
      return std::nullopt;
    }
    for (const VelodynePacketView& packet : scan.packets) {
      // A driver that left the packet stamps at 0 still gave the message a time.
      assembler_.add_packet(packet.data.data,
                            packet.stamp_ns != 0 ? packet.stamp_ns : scan.stamp_ns);
    }
    return assembler_.take();
  }

  std::optional<Scan> finish(const DecodeReport& report) override {
    assembler_.flush();
    if (assembler_.decoder().bad_blocks() > 0) {
      report.warn(std::to_string(assembler_.decoder().bad_blocks()) +
                  " Velodyne data blocks with a flag or azimuth the model does not use; skipped");
    }
    return assembler_.take();
  }

  std::optional<Scan> take_pending() override { return assembler_.take(); }

 private:
  VelodyneScanAssembler assembler_;
  MessageEncoding encoding_;
};

}  // namespace

std::unique_ptr<BagScanDecoder> make_velodyne_scan_decoder(const BagTopicContext& context,
                                                           SourceInfo& info) {
  std::vector<uint8_t> first_packet;
  std::unique_ptr<MessageCursor> messages = context.open_topic(context.topic);
  std::string problem;
  while (const std::optional<BagMessage> message = messages->next()) {
    try {
      const VelodyneScanView scan = parse_velodyne_scan(message->data, context.topic.encoding);
      if (scan.packets.empty()) continue;
      const ByteView data = scan.packets.front().data;
      first_packet.assign(data.data, data.data + data.size);
      break;
    } catch (const SerializationError& e) {
      if (problem.empty()) problem = e.what();
    }
  }
  if (first_packet.empty()) {
    throw InputError(context.origin + ": no readable Velodyne packet on " + context.topic.name +
                     (problem.empty() ? std::string() : " (first problem: " + problem + ")"));
  }
  const VelodyneSetup setup =
      velodyne_setup(first_packet.data(), context.options, sensor_for, context.origin);
  info.sensor = setup.sensor;
  info.sensor_from_metadata = true;
  info.fields = velodyne_fields();
  info.frames.reset();
  info.detail = setup.detail;
  info.times = "per point, from the firing timing of the packets";
  return std::make_unique<VelodyneScanDecoder>(setup, context.topic.encoding);
}

}  // namespace featsense::slam
