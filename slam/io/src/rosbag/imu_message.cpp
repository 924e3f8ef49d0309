#include "rosbag/imu_message.hpp"

#include <cstring>
#include <string>

#include "ros2/cdr_deserializer.hpp"

namespace featsense::slam {
namespace {

double as_double(uint64_t bits) {
  double value = 0.0;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

/// The fields after the header, the same in both encodings but for CDR's alignment (which
/// the deserializer applies itself).
template <typename Deserializer>
ImuSample read_body(Deserializer& in, int64_t stamp_ns) {
  const auto f64 = [&in](const char* what) { return as_double(in.u64(what)); };
  const auto vector3 = [&f64](const char* what) {
    const double x = f64(what);
    const double y = f64(what);
    const double z = f64(what);
    return Eigen::Vector3d(x, y, z);
  };
  for (int i = 0; i < 4; ++i) f64("orientation");
  for (int i = 0; i < 9; ++i) f64("orientation_covariance");
  ImuSample sample;
  sample.stamp_ns = stamp_ns;
  sample.gyro_radps = vector3("angular_velocity");
  for (int i = 0; i < 9; ++i) f64("angular_velocity_covariance");
  sample.accel_mps2 = vector3("linear_acceleration");
  for (int i = 0; i < 9; ++i) f64("linear_acceleration_covariance");
  return sample;
}

class ImuMessageTopicDecoder final : public ImuMessageDecoder {
 public:
  ImuMessageTopicDecoder(MessageEncoding encoding, const Eigen::Matrix3d& imu_to_sensor)
      : encoding_(encoding), imu_to_sensor_(imu_to_sensor) {}

  std::optional<ImuSample> decode(const BagMessage& message, const DecodeReport& report) override {
    ImuSample sample;
    try {
      sample = imu_message(message.data, encoding_);
    } catch (const SerializationError& e) {
      report.warn("IMU message at offset " + std::to_string(message.offset) + ": " + e.what());
      return std::nullopt;
    }
    if (!sample.accel_mps2.allFinite() || !sample.gyro_radps.allFinite()) {
      report.warn("IMU message at offset " + std::to_string(message.offset) +
                  " holds a non-finite value; ignored");
      return std::nullopt;
    }
    sample.accel_mps2 = imu_to_sensor_ * sample.accel_mps2;
    sample.gyro_radps = imu_to_sensor_ * sample.gyro_radps;
    return sample;
  }

 private:
  MessageEncoding encoding_;
  Eigen::Matrix3d imu_to_sensor_;
};

}  // namespace

ImuSample imu_message(ByteView message, MessageEncoding encoding) {
  if (encoding == MessageEncoding::kCdr) {
    CdrDeserializer in(message);
    const int64_t stamp_ns = in.time_ns("header.stamp");
    in.string("header.frame_id");
    return read_body(in, stamp_ns);
  }
  RosDeserializer in(message);
  in.u32("header.seq");
  const int64_t stamp_ns = in.time_ns("header.stamp");
  in.string("header.frame_id");
  return read_body(in, stamp_ns);
}

std::unique_ptr<ImuMessageDecoder> make_imu_message_decoder(MessageEncoding encoding,
                                                            const Eigen::Matrix3d& imu_to_sensor) {
  return std::make_unique<ImuMessageTopicDecoder>(encoding, imu_to_sensor);
}

}  // namespace featsense::slam
