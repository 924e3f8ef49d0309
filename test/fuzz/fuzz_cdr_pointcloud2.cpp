// Fuzzes the CDR decoding of sensor_msgs/msg/PointCloud2 and what follows it (the layout
// check and the conversion to scan data), and of the other CDR messages the readers take
// (VelodyneScan, PacketMsg, String), over arbitrary bytes. Anything but a
// SerializationError escaping, a sanitizer report, or a hang is a bug.

#include <cstddef>
#include <cstdint>

#include "ros2/cdr_pointcloud2.hpp"
#include "rosbag/pointcloud2.hpp"
#include "rosbag/pointcloud2_convert.hpp"
#include "rosbag/simple_messages.hpp"
#include "velodyne/velodyne_scan_message.hpp"

using namespace featsense::slam;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const ByteView bytes{data, size};
  try {
    const PointCloud2View cloud = parse_pointcloud2_cdr(bytes);
    if (layout_problem(cloud).empty()) {
      if (cloud.height > 1) {
        organized_cloud_to_scan(cloud, 0);
      } else {
        cloud_to_points(cloud, 0);
      }
    }
  } catch (const SerializationError&) {
  }
  try {
    parse_velodyne_scan(bytes, MessageEncoding::kCdr);
  } catch (const SerializationError&) {
  }
  try {
    byte_array_message(bytes, MessageEncoding::kCdr);
    string_message(bytes, MessageEncoding::kCdr);
  } catch (const SerializationError&) {
  }
  return 0;
}
