// open_rosbag(): the bag source with the library's organizer, presets and Ouster decoder.

#include "featsense/slam/io/organize.hpp"
#include "featsense/slam/io/readers.hpp"
#include "rosbag/rosbag_ouster_packets.hpp"
#include "rosbag/rosbag_source.hpp"

namespace featsense::slam {

std::unique_ptr<ScanSource> open_rosbag(const std::string& path, const SourceOptions& options) {
  RosbagDependencies dependencies;
  dependencies.organize = [](const PointCloud& cloud, const config::SensorModel& sensor) {
    return organize(cloud, sensor);
  };
  dependencies.sensor_for = sensor_for;
  dependencies.ouster_packets = make_ouster_packet_decoder;
  return open_rosbag_source(path, options, dependencies);
}

}  // namespace featsense::slam
