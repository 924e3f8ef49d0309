#pragma once
/// Raw Velodyne packets in a bag: a topic of velodyne_msgs/VelodyneScan (ROS 1 or ROS 2),
/// its packets fed in order to a VelodyneScanAssembler.

#include <memory>

#include "featsense/slam/scan_source.hpp"
#include "rosbag/bag_scan_decoder.hpp"

namespace featsense::slam {

/// The decoder of a VelodyneScan topic: the model from the first packet's product id (else
/// sensor.preset), the calibration from sensor.calibration (else built in). Fills
/// info.sensor, info.fields, info.detail and info.times. Throws InputError where the topic
/// holds no readable packet or the model cannot be told.
std::unique_ptr<BagScanDecoder> make_velodyne_scan_decoder(const BagTopicContext& context,
                                                           SourceInfo& info);

}  // namespace featsense::slam
