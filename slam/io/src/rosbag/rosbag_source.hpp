#pragma once
/// The ScanSource of a ROS1 bag: catalogs the bag, chooses the topic, and streams that
/// topic's messages through the decoder of its type.

#include <functional>
#include <memory>
#include <string>

#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/scan_source.hpp"
#include "rosbag/bag_scan_decoder.hpp"
#include "rosbag/pointcloud2_decoder.hpp"

namespace featsense::slam {

/// Builds the decoder of an Ouster lidar packet topic and fills info's sensor, fields and
/// detail (rosbag_ouster_packets.hpp).
using PacketDecoderFactory = std::function<std::unique_ptr<BagScanDecoder>(
    const BagTopicContext& context, SourceInfo& info)>;

/// The parts of the slam library that the bag source hands work to: organizing unorganized
/// clouds, sensor presets, and assembling Ouster packets into frames. open_rosbag() passes
/// the real ones; they are parameters so that the bag reading stands on its own.
struct RosbagDependencies {
  CloudOrganizer organize;              ///< organize() of organize.hpp
  SensorLookup sensor_for;              ///< sensor_for() of readers.hpp
  PacketDecoderFactory ouster_packets;  ///< make_ouster_packet_decoder()
};

/// open_rosbag() with its dependencies given. Throws InputError.
std::unique_ptr<ScanSource> open_rosbag_source(const std::string& path,
                                               const SourceOptions& options,
                                               const RosbagDependencies& dependencies);

}  // namespace featsense::slam
