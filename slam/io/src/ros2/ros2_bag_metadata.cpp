#include "ros2/ros2_bag_metadata.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {

Ros2BagMetadata read_ros2_bag_metadata(const std::string& folder) {
  namespace fs = std::filesystem;
  const std::string path = (fs::path(folder) / "metadata.yaml").string();
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw InputError(path + ": not readable as YAML (" + e.what() + ")");
  }
  const YAML::Node info = root["rosbag2_bagfile_information"];
  if (!info || !info.IsMap()) {
    throw InputError(path + ": no 'rosbag2_bagfile_information' (not a ROS 2 bag's metadata)");
  }
  Ros2BagMetadata metadata;
  try {
    metadata.storage = info["storage_identifier"].as<std::string>("sqlite3");
    const std::string compression = info["compression_format"].as<std::string>("");
    if (!compression.empty()) {
      throw InputError(path + ": the bag is compressed (compression_format '" + compression +
                       "', mode '" + info["compression_mode"].as<std::string>("") +
                       "'), which is not supported; decompress it first (ros2 bag convert)");
    }
    const YAML::Node files = info["relative_file_paths"];
    if (!files || !files.IsSequence() || files.size() == 0) {
      throw InputError(path + ": 'relative_file_paths' lists no file");
    }
    for (const YAML::Node& file : files) {
      const fs::path full = fs::path(folder) / file.as<std::string>();
      if (!fs::is_regular_file(full)) {
        throw InputError(path + ": lists the file " + file.as<std::string>() +
                         " (relative_file_paths), which is missing from " + folder);
      }
      metadata.files.push_back(full.string());
    }
  } catch (const YAML::Exception& e) {
    throw InputError(path + ": " + e.what());
  }
  if (metadata.storage != "sqlite3" && metadata.storage != "mcap") {
    throw InputError(path + ": storage_identifier '" + metadata.storage +
                     "' is not supported (sqlite3 or mcap)");
  }
  return metadata;
}

}  // namespace featsense::slam
