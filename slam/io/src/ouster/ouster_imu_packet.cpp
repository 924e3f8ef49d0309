#include "ouster/ouster_imu_packet.hpp"

#include <cmath>
#include <cstring>

#include "ouster/byte_order.hpp"

namespace featsense::slam::detail {
namespace {

constexpr double kStandardGravity = 9.80665;  // m/s^2 per g
constexpr double kDegToRad = M_PI / 180.0;

constexpr size_t kGyroTimestampOffset = 16;
constexpr size_t kAccelOffset = 24;
constexpr size_t kGyroOffset = 36;

float load_le_float(const uint8_t* data) {
  const uint32_t bits = load_le<uint32_t>(data);
  float value = 0.0f;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

Eigen::Vector3d load_le_vector(const uint8_t* data) {
  return Eigen::Vector3d(load_le_float(data), load_le_float(data + 4), load_le_float(data + 8));
}

}  // namespace

Eigen::Matrix3d ouster_imu_to_sensor_rotation(const OusterMetadata& metadata) {
  Eigen::Matrix3d rotation;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      rotation(r, c) = metadata.imu_to_sensor[static_cast<size_t>(4 * r + c)];
  }
  return rotation;
}

std::optional<ImuSample> decode_ouster_imu_packet(const uint8_t* data, size_t size,
                                                  const Eigen::Matrix3d& imu_to_sensor) {
  if (data == nullptr || size != kOusterImuPacketBytes) return std::nullopt;
  ImuSample sample;
  sample.stamp_ns = static_cast<int64_t>(load_le<uint64_t>(data + kGyroTimestampOffset));
  sample.accel_mps2 = imu_to_sensor * (load_le_vector(data + kAccelOffset) * kStandardGravity);
  sample.gyro_radps = imu_to_sensor * (load_le_vector(data + kGyroOffset) * kDegToRad);
  if (!sample.accel_mps2.allFinite() || !sample.gyro_radps.allFinite()) return std::nullopt;
  return sample;
}

}  // namespace featsense::slam::detail
