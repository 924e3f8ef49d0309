#include "rosbag/pointcloud2.hpp"

#include <algorithm>

namespace featsense::slam {

size_t point_field_size(uint8_t datatype) {
  switch (static_cast<PointFieldType>(datatype)) {
    case PointFieldType::kInt8:
    case PointFieldType::kUint8:
      return 1;
    case PointFieldType::kInt16:
    case PointFieldType::kUint16:
      return 2;
    case PointFieldType::kInt32:
    case PointFieldType::kUint32:
    case PointFieldType::kFloat32:
      return 4;
    case PointFieldType::kFloat64:
      return 8;
  }
  return 0;
}

bool point_field_is_float(uint8_t datatype) {
  return datatype == static_cast<uint8_t>(PointFieldType::kFloat32) ||
         datatype == static_cast<uint8_t>(PointFieldType::kFloat64);
}

const PointFieldDesc* PointCloud2View::field(std::string_view name) const {
  for (const PointFieldDesc& f : fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

PointCloud2View parse_pointcloud2(ByteView message) {
  RosDeserializer in(message);
  PointCloud2View cloud;
  cloud.seq = in.u32("header.seq");
  cloud.stamp_ns = in.time_ns("header.stamp");
  cloud.frame_id = in.string("header.frame_id");
  read_pointcloud2_body(in, cloud);
  return cloud;
}

std::string layout_problem(const PointCloud2View& cloud) {
  if (cloud.is_bigendian) return "big-endian cloud (not supported)";
  if (cloud.height == 0 || cloud.width == 0) {
    return "empty cloud (" + std::to_string(cloud.height) + " x " + std::to_string(cloud.width) +
           ")";
  }
  const uint64_t points = uint64_t{cloud.height} * cloud.width;
  if (points > kMaxCloudPoints) {
    return std::to_string(points) + " points, more than the limit of " +
           std::to_string(kMaxCloudPoints);
  }
  for (const char* name : {"x", "y", "z"}) {
    if (cloud.field(name) == nullptr) return std::string("no '") + name + "' field";
  }
  for (const PointFieldDesc& field : cloud.fields) {
    const size_t size = point_field_size(field.datatype);
    if (size == 0) {
      return "field '" + field.name + "' has unknown datatype " +
             std::to_string(static_cast<int>(field.datatype));
    }
    const uint64_t end = uint64_t{field.offset} + size * std::max<uint64_t>(field.count, 1);
    if (end > cloud.point_step) {
      return "field '" + field.name + "' ends at byte " + std::to_string(end) +
             ", past point_step " + std::to_string(cloud.point_step);
    }
  }
  const uint64_t row_bytes = uint64_t{cloud.width} * cloud.point_step;
  if (cloud.height > 1 && cloud.row_step < row_bytes) {
    return "row_step " + std::to_string(cloud.row_step) + " is shorter than width " +
           std::to_string(cloud.width) + " x point_step " + std::to_string(cloud.point_step);
  }
  const uint64_t needed = uint64_t{cloud.height - 1} * cloud.row_step + row_bytes;
  if (cloud.data.size < needed) {
    return "data holds " + std::to_string(cloud.data.size) + " bytes, the layout needs " +
           std::to_string(needed);
  }
  return "";
}

}  // namespace featsense::slam
