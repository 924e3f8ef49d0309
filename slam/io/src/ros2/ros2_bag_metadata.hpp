#pragma once
/// The metadata.yaml of a ROS 2 bag folder (rosbag2_bagfile_information, versions 1 to 9):
/// which storage the bag uses and which files hold it, in recording order.

#include <string>
#include <vector>

namespace featsense::slam {

struct Ros2BagMetadata {
  std::string storage;             ///< storage_identifier: "sqlite3" or "mcap"
  std::vector<std::string> files;  ///< full paths, in the order metadata.yaml lists them
};

/// Reads `folder`/metadata.yaml. Throws InputError naming the file and key where it is
/// missing, unreadable, lists a file that does not exist, or describes a compressed bag.
Ros2BagMetadata read_ros2_bag_metadata(const std::string& folder);

}  // namespace featsense::slam
