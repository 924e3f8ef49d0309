#include "velodyne/velodyne_scan_message.hpp"

#include "ros2/cdr_deserializer.hpp"
#include "velodyne/velodyne_model.hpp"

namespace featsense::slam {
namespace {

/// The same fields in either serialization; `In` is RosDeserializer or CdrDeserializer.
template <typename In>
VelodyneScanView parse(In& in, bool ros1) {
  VelodyneScanView scan;
  if (ros1) in.u32("header.seq");
  scan.stamp_ns = in.time_ns("header.stamp");
  scan.frame_id = in.string("header.frame_id");
  const uint32_t count = in.u32("packets count");
  // No reserve(count): a lying count ends in a SerializationError once the data runs out.
  for (uint32_t i = 0; i < count; ++i) {
    VelodynePacketView packet;
    packet.stamp_ns = in.time_ns("packet stamp");
    packet.data = in.bytes(kVelodynePacketBytes, "packet data");
    scan.packets.push_back(packet);
  }
  return scan;
}

}  // namespace

VelodyneScanView parse_velodyne_scan(ByteView message, MessageEncoding encoding) {
  if (encoding == MessageEncoding::kCdr) {
    CdrDeserializer in(message);
    return parse(in, false);
  }
  RosDeserializer in(message);
  return parse(in, true);
}

}  // namespace featsense::slam
