#pragma once
/// Which topic of a bag holds the IMU's samples that go with the scans, and its decoder.

#include <Eigen/Core>

#include <array>
#include <memory>
#include <string>

#include "featsense/slam/io/open_scan_source.hpp"
#include "rosbag/bag_catalog.hpp"
#include "rosbag/bag_scan_decoder.hpp"

namespace featsense::slam {

struct BagImuTopic {
  const BagTopic* topic = nullptr;  ///< nullptr: no IMU read
  std::unique_ptr<ImuMessageDecoder> decoder;
  /// Where the samples come from and in which frame, for SourceInfo::imu; where none is read
  /// although the bag has IMU topics, why not.
  std::string description;
};

/// The IMU topic of a bag: options.imu_topic where given (it must exist and hold Ouster IMU
/// packets or sensor_msgs/Imu), else for Ouster lidar packets the IMU packets of the same
/// driver, else the one sensor_msgs/Imu topic there is (several: none, and the description
/// says so). Ouster packets are turned into the sensor frame with the metadata's
/// imu_to_sensor_transform, sensor_msgs/Imu by options.imu_rotation_deg. Nothing where
/// options.imu is false. Throws InputError for an imu_topic that is unknown or no IMU's.
BagImuTopic choose_imu_topic(const BagCatalog& catalog, const BagTopic& scans,
                             const BagScanDecoder& scan_decoder, const SourceOptions& options,
                             const std::string& origin);

/// The rotation of roll, pitch, yaw in degrees (about x, then y, then z: R = Rz Ry Rx).
Eigen::Matrix3d rotation_from_roll_pitch_yaw_deg(const std::array<double, 3>& roll_pitch_yaw);

}  // namespace featsense::slam
