#include "ros2/cdr_pointcloud2.hpp"

#include "ros2/cdr_deserializer.hpp"

namespace featsense::slam {

PointCloud2View parse_pointcloud2_cdr(ByteView message) {
  CdrDeserializer in(message);
  PointCloud2View cloud;
  cloud.stamp_ns = in.time_ns("header.stamp");
  cloud.frame_id = in.string("header.frame_id");
  read_pointcloud2_body(in, cloud);
  return cloud;
}

}  // namespace featsense::slam
