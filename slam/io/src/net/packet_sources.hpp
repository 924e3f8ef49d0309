#pragma once
// The Ouster and Velodyne readers over any DatagramFeed (a pcap file, a socket).

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "featsense/slam/io/ouster_metadata.hpp"
#include "featsense/slam/scan_source.hpp"
#include "net/datagram_feed.hpp"
#include "velodyne/velodyne_setup.hpp"

namespace featsense::slam::detail {

/// Lidar packets are the datagrams of the metadata's packet size, IMU packets (with
/// `read_imu`) those on `imu_port` (else the metadata's udp_port_imu). `format` names the
/// input in SourceInfo ("ouster-pcap", "ouster-live").
std::unique_ptr<ScanSource> ouster_packet_source(std::unique_ptr<DatagramFeed> feed,
                                                 std::string format,
                                                 const std::filesystem::path& meta_path,
                                                 OusterMetadata metadata, bool read_imu,
                                                 std::optional<int> imu_port = std::nullopt);

/// The 1206-byte data packets, decoded and cut into scans as `setup` says.
std::unique_ptr<ScanSource> velodyne_packet_source(std::unique_ptr<DatagramFeed> feed,
                                                   std::string format, const VelodyneSetup& setup);

/// The Ouster metadata JSON at `path`, parsed; throws InputError naming the file.
OusterMetadata read_ouster_metadata(const std::filesystem::path& path);

}  // namespace featsense::slam::detail
