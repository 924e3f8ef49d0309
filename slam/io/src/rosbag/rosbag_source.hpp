#pragma once
/// The ScanSource of a ROS1 bag: catalogs the bag and streams the chosen topic's messages
/// through the decoder of its type (message_log.hpp).

#include <memory>
#include <string>

#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/scan_source.hpp"
#include "rosbag/message_log.hpp"

namespace featsense::slam {

/// open_rosbag() with its dependencies given. Throws InputError.
std::unique_ptr<ScanSource> open_rosbag_source(const std::string& path,
                                               const SourceOptions& options,
                                               const RosbagDependencies& dependencies);

}  // namespace featsense::slam
