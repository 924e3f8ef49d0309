#pragma once
/// Raw Ouster packets in a bag: a topic of ouster_ros/PacketMsg (u8[] buf = one UDP
/// payload) decoded with the sensor's metadata JSON into frames by OusterFrameAssembler.

#include <memory>

#include "featsense/slam/scan_source.hpp"
#include "rosbag/bag_scan_decoder.hpp"

namespace featsense::slam {

/// The decoder of an Ouster lidar packet topic. The metadata is the file
/// options.meta_path where the user gave one (an explicit choice wins), else the first
/// message of the bag's metadata topic (std_msgs/String in the packet topic's namespace,
/// e.g. /os_node0/metadata). Fills info.sensor (from the metadata), info.fields and
/// info.detail. Throws InputError where no metadata is found or it cannot be parsed.
std::unique_ptr<BagScanDecoder> make_ouster_packet_decoder(const BagTopicContext& context,
                                                           SourceInfo& info);

}  // namespace featsense::slam
