#pragma once
// Ouster IMU packets (the legacy layout of firmware 2.x, 48 bytes): three little-endian
// uint64 timestamps in ns (system, accelerometer, gyroscope), the accelerometer's x, y, z as
// float32 in g, the gyroscope's x, y, z as float32 in deg/s. Shared by the pcap reader and the
// ROS bag reader (raw PacketMsg topics).

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <optional>

#include "featsense/slam/imu_sample.hpp"
#include "featsense/slam/io/ouster_metadata.hpp"

namespace featsense::slam::detail {

constexpr size_t kOusterImuPacketBytes = 48;

/// The rotation part of the metadata's imu_to_sensor_transform.
Eigen::Matrix3d ouster_imu_to_sensor_rotation(const OusterMetadata& metadata);

/// The sample of one IMU packet in the sensor frame (m/s^2, rad/s), stamped with the
/// gyroscope's timestamp: the clock of the lidar columns' timestamps. Only the rotation of
/// imu_to_sensor is applied: the lever arm (about 2 cm) would add the centripetal term
/// w x (w x r), below 0.01 m/s^2 even at 1 rad/s, and a term in the angular acceleration
/// that the samples cannot tell. Nullopt where the packet is not 48 bytes or holds a
/// non-finite value.
std::optional<ImuSample> decode_ouster_imu_packet(const uint8_t* data, size_t size,
                                                  const Eigen::Matrix3d& imu_to_sensor);

}  // namespace featsense::slam::detail
