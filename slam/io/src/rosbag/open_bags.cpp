// The public openers of bags and MCAP files: the containers with the library's organizer,
// presets and packet decoders.

#include <filesystem>
#include <vector>

#include "featsense/slam/io/organize.hpp"
#include "featsense/slam/io/readers.hpp"
#include "mcap/mcap_message_log.hpp"
#include "ros2/ros2_bag_metadata.hpp"
#include "ros2/split_bag_log.hpp"
#include "ros2/sqlite_bag_log.hpp"
#include "rosbag/rosbag_ouster_packets.hpp"
#include "rosbag/rosbag_source.hpp"
#include "velodyne/velodyne_bag_packets.hpp"

namespace featsense::slam {
namespace {

RosbagDependencies library_dependencies() {
  RosbagDependencies dependencies;
  dependencies.organize = [](const PointCloud& cloud, const config::SensorModel& sensor) {
    return organize(cloud, sensor);
  };
  dependencies.sensor_for = sensor_for;
  dependencies.ouster_packets = make_ouster_packet_decoder;
  dependencies.velodyne_packets = make_velodyne_scan_decoder;
  return dependencies;
}

}  // namespace

std::unique_ptr<ScanSource> open_rosbag(const std::string& path, const SourceOptions& options) {
  return open_rosbag_source(path, options, library_dependencies());
}

std::unique_ptr<ScanSource> open_ros2_bag(const std::string& path, const SourceOptions& options) {
  namespace fs = std::filesystem;
  std::vector<std::unique_ptr<MessageLog>> files;
  std::string storage = "sqlite3";
  if (fs::is_directory(path)) {
    const Ros2BagMetadata metadata = read_ros2_bag_metadata(path);
    storage = metadata.storage;
    for (const std::string& file : metadata.files) {
      files.push_back(storage == "mcap" ? open_mcap_file(file) : open_sqlite_bag_file(file));
    }
  } else {
    files.push_back(open_sqlite_bag_file(path));
  }
  SourceInfo info;
  info.format = "ros2-bag";
  info.path = path;
  return open_message_log_source(join_bag_files(std::move(files)), std::move(info), options,
                                 library_dependencies());
}

std::unique_ptr<ScanSource> open_mcap(const std::string& path, const SourceOptions& options) {
  SourceInfo info;
  info.format = "mcap";
  info.path = path;
  return open_message_log_source(open_mcap_file(path), std::move(info), options,
                                 library_dependencies());
}

}  // namespace featsense::slam
