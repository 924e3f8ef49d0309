#pragma once
/// One opener per format; open_scan_source() detects the format and calls one of these.
/// Each throws InputError when the input cannot be read at all.

#include <memory>
#include <string>

#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {

/// An Ouster pcap; the metadata JSON is options.meta_path, else the .json in the same folder
/// whose name shares the longest prefix with the pcap's. Lidar packets are the UDP payloads of
/// the size the metadata implies, on any port. A capture that yields no frame at all (no such
/// packet, or cut before the first) throws InputError from next(), naming the sizes it saw; a
/// capture cut later ends with a counted warning after the frames before the cut. With
/// options.imu, the IMU packets on the metadata's udp_port_imu go with the scan of their
/// sweep (Scan::imu), turned into the sensor frame by its imu_to_sensor_transform; a packet
/// of another size there is skipped with a counted warning.
std::unique_ptr<ScanSource> open_ouster_pcap(const std::string& path, const SourceOptions& options);
/// A Velodyne pcap (VeloView or tcpdump): the 1206-byte UDP data packets of a VLP-16,
/// VLP-32C, HDL-32E, HDL-64E or VLS-128, decoded with sensor.calibration (else the model's
/// built-in table) and cut into scans at sensor.scan_cut_deg.
std::unique_ptr<ScanSource> open_velodyne_pcap(const std::string& path,
                                               const SourceOptions& options);
/// True where the first UDP datagrams of a pcap include a Velodyne data packet.
bool is_velodyne_pcap(const std::string& path);
/// A ROS1 bag (format 2.0): sensor_msgs/PointCloud2, velodyne_msgs/VelodyneScan or raw
/// ouster_ros/PacketMsg topics. With options.imu, the IMU's samples (Ouster IMU packets, or
/// a sensor_msgs/Imu topic: bag_imu_topic.hpp) go with the scan of their sweep.
std::unique_ptr<ScanSource> open_rosbag(const std::string& path, const SourceOptions& options);
/// A ROS 2 bag: its folder (metadata.yaml + .db3 or .mcap files, read in the order the
/// metadata lists them) or one .db3 file. Topics as in open_rosbag(), serialized as CDR.
std::unique_ptr<ScanSource> open_ros2_bag(const std::string& path, const SourceOptions& options);
/// An MCAP file (chunks uncompressed, zstd or lz4; with or without a summary) of ROS 2 (CDR)
/// or ROS 1 messages; topics as in open_rosbag().
std::unique_ptr<ScanSource> open_mcap(const std::string& path, const SourceOptions& options);
/// One PCD file (one frame).
std::unique_ptr<ScanSource> open_pcd_file(const std::string& path, const SourceOptions& options);
/// One PLY point cloud (one frame).
std::unique_ptr<ScanSource> open_ply_file(const std::string& path, const SourceOptions& options);
/// A folder of scans: KITTI .bin, PCD or PLY files in name order, or a folder written by
/// `featsense simulate` (it holds a sequence.yaml). Mixed formats are an error. Stamps come
/// from the file names, else KITTI's times.txt beside the scans or one folder up (the
/// instants the laser faced +x: times derived from the azimuth count from there), else the
/// files' own, else the frame's index over the rate.
std::unique_ptr<ScanSource> open_scan_folder(const std::string& path, const SourceOptions& options);

/// The sensor model a reader should use for a recording without metadata: the preset named
/// in options (when not "auto"), else `fallback_preset`.
config::SensorModel sensor_for(const SourceOptions& options, const std::string& fallback_preset);

}  // namespace featsense::slam
