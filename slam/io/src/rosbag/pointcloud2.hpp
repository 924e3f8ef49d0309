#pragma once
/// sensor_msgs/PointCloud2: Header, u32 height, u32 width, PointField[] fields (string name,
/// u32 offset, u8 datatype, u32 count), u8 is_bigendian, u32 point_step, u32 row_step,
/// u8[] data, u8 is_dense.

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rosbag/ros_serialization.hpp"

namespace featsense::slam {

/// PointField datatypes: 1 int8, 2 uint8, 3 int16, 4 uint16, 5 int32, 6 uint32, 7 float32,
/// 8 float64.
enum class PointFieldType : uint8_t {
  kInt8 = 1,
  kUint8 = 2,
  kInt16 = 3,
  kUint16 = 4,
  kInt32 = 5,
  kUint32 = 6,
  kFloat32 = 7,
  kFloat64 = 8,
};

/// Bytes of one element of a datatype; 0 for a value outside 1..8.
size_t point_field_size(uint8_t datatype);
/// True for the two floating-point datatypes.
bool point_field_is_float(uint8_t datatype);

struct PointFieldDesc {
  std::string name;
  uint32_t offset = 0;   ///< bytes from the start of a point
  uint8_t datatype = 0;  ///< PointFieldType
  uint32_t count = 0;    ///< elements (1 for a scalar)
};

/// A parsed message; the point data is viewed in place (in the chunk it came from).
struct PointCloud2View {
  uint32_t seq = 0;
  int64_t stamp_ns = 0;  ///< header stamp, ns since the epoch
  std::string frame_id;
  uint32_t height = 0;  ///< rows; 1 for an unorganized cloud
  uint32_t width = 0;   ///< points per row
  std::vector<PointFieldDesc> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0;  ///< bytes per point
  uint32_t row_step = 0;    ///< bytes per row
  ByteView data;
  bool is_dense = false;

  /// The first field of that name, or nullptr.
  const PointFieldDesc* field(std::string_view name) const;
  size_t points() const { return static_cast<size_t>(height) * width; }
  /// The first byte of point (row, col); valid once layout_problem() said nothing.
  const uint8_t* point(uint32_t row, uint32_t col) const {
    return data.data + static_cast<size_t>(row) * row_step + static_cast<size_t>(col) * point_step;
  }
};

/// Parses a serialized PointCloud2; throws SerializationError when it ends early.
PointCloud2View parse_pointcloud2(ByteView message);

/// Clouds with more points than this are rejected (a corrupt size, or not one scan).
constexpr size_t kMaxCloudPoints = size_t{1} << 24;

/// Why the cloud cannot be read, or "" when it can: big-endian data, no points or too many,
/// no x/y/z, a field past point_step or of an unknown datatype, row_step or data too short
/// for width x height points. Once it returns "", every point's fields lie inside `data`.
std::string layout_problem(const PointCloud2View& cloud);

/// The fields after the header, the same in ROS 1 and in CDR: `In` is RosDeserializer or
/// CdrDeserializer (which aligns them). Throws SerializationError.
template <typename In>
void read_pointcloud2_body(In& in, PointCloud2View& cloud) {
  cloud.height = in.u32("height");
  cloud.width = in.u32("width");
  const uint32_t field_count = in.u32("fields count");
  // No reserve(field_count): the count is unchecked, and each field needs at least 13 bytes,
  // so a lying count ends in a SerializationError after as many fields as the data holds.
  for (uint32_t i = 0; i < field_count; ++i) {
    PointFieldDesc field;
    field.name = in.string("field name");
    field.offset = in.u32("field offset");
    field.datatype = in.u8("field datatype");
    field.count = in.u32("field count");
    cloud.fields.push_back(std::move(field));
  }
  cloud.is_bigendian = in.u8("is_bigendian") != 0;
  cloud.point_step = in.u32("point_step");
  cloud.row_step = in.u32("row_step");
  cloud.data = in.bytes(in.u32("data count"), "data");
  cloud.is_dense = in.u8("is_dense") != 0;
}

}  // namespace featsense::slam
