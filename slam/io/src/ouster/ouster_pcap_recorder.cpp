// Scans -> Ouster lidar and IMU packets (PACKET_FORMAT.md, RNG19_RFL8_SIG16_NIR16) in a pcap,
// and the metadata that describes them.

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/pcap_recorders.hpp"
#include "net/pcap_writer.hpp"
#include "ouster/byte_order.hpp"
#include "ouster/ouster_imu_packet.hpp"
#include "ouster/ouster_packet.hpp"

namespace featsense::slam {
namespace {

using detail::store_le_bytes;

constexpr int kColumnsPerPacket = 16;
using detail::kOusterImuPacketBytes;
constexpr uint32_t kMaxRangeMm = (1u << 19) - 1;
constexpr uint16_t kLidarDataPacketType = 1;
constexpr uint16_t kLidarPort = 7502;
constexpr uint16_t kImuPort = 7503;
constexpr double kStandardGravity = 9.80665;  // m/s^2 per g, as the reader divides
// The identity the packets' headers and the metadata share (made up: no unit has it).
constexpr uint64_t kSerial = 990000000001ull;
constexpr uint64_t kInitializationId = 7109750;

void put_float(uint8_t* at, double value) {
  const float f = static_cast<float>(value);
  uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  store_le_bytes(at, bits, 4);
}

/// "os1-128" -> "OS-1-128", Ouster's way of writing a product line; other names as they are.
std::string product_line(const std::string& name) {
  if (name.size() > 3 && (name.rfind("os", 0) == 0 || name.rfind("OS", 0) == 0) &&
      std::isdigit(static_cast<unsigned char>(name[2]))) {
    std::string line = "OS-" + name.substr(2);
    std::transform(line.begin(), line.end(), line.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    return line;
  }
  return name;
}

/// The byte layout of the packets written: the reader's for the profile and geometry.
detail::OusterPacketLayout packet_layout(const config::SensorModel& sensor) {
  OusterMetadata metadata;
  metadata.profile = OusterProfile::kRng19Rfl8Sig16Nir16;
  metadata.pixels_per_column = sensor.beams;
  metadata.columns_per_packet = kColumnsPerPacket;
  return detail::OusterPacketLayout::of(metadata);
}

uint16_t clamp_u16(float value) {
  if (!(value > 0.0f)) return 0;
  return static_cast<uint16_t>(std::min(65535.0f, std::round(value)));
}

}  // namespace

struct OusterPcapRecorder::State {
  State(const std::string& path, config::SensorModel s)
      : sensor(std::move(s)), layout(packet_layout(sensor)), pcap(path) {}

  config::SensorModel sensor;
  detail::OusterPacketLayout layout;
  int rate_hz = 10;
  detail::PcapWriter pcap;
  uint16_t frame_id = 0;
  uint64_t lidar_packets = 0;
  uint64_t imu_packets = 0;
  bool imu_written = false;
  int64_t last_imu_stamp_ns = 0;
  std::vector<uint8_t> packet;
};

OusterPcapRecorder::OusterPcapRecorder(const std::string& pcap_path, config::SensorModel sensor) {
  sensor.validate();
  const double rate = sensor.rate_hz;
  if (std::abs(rate - std::round(rate)) > 1e-9 || rate < 1.0) {
    throw config::ConfigError("an Ouster sensor turns a whole number of times per second (its " +
                              std::string("lidar_mode, e.g. 1024x10); the rate is ") +
                              std::to_string(rate) + " Hz");
  }
  if (sensor.columns > 65535 || sensor.beams > 4095) {
    throw config::ConfigError(
        "an Ouster packet holds at most 65,535 columns of 4,095 beams; the "
        "sensor has " +
        std::to_string(sensor.columns) + " x " + std::to_string(sensor.beams));
  }
  if (sensor.azimuth_offset_rad.empty())
    sensor.azimuth_offset_rad.assign(static_cast<size_t>(sensor.beams), 0.0);
  state_ = std::make_unique<State>(pcap_path, std::move(sensor));
  state_->rate_hz = static_cast<int>(std::lround(rate));
}

OusterPcapRecorder::~OusterPcapRecorder() = default;

uint64_t OusterPcapRecorder::lidar_packets() const { return state_->lidar_packets; }
uint64_t OusterPcapRecorder::imu_packets() const { return state_->imu_packets; }

std::string OusterPcapRecorder::metadata_json() const {
  const config::SensorModel& s = state_->sensor;
  constexpr double kDeg = 180.0 / M_PI;
  nlohmann::json altitude = nlohmann::json::array();
  nlohmann::json azimuth = nlohmann::json::array();
  for (int r = 0; r < s.beams; ++r) {
    altitude.push_back(s.elevation_rad[static_cast<size_t>(r)] * kDeg);
    // Ouster's beam azimuth turns the other way (theta_a = -2 pi azimuth / 360).
    azimuth.push_back(-s.azimuth_offset_rad[static_cast<size_t>(r)] * kDeg);
  }
  const double n_mm = s.beam_origin_offset_m * 1000.0;
  const std::string mode = std::to_string(s.columns) + "x" + std::to_string(state_->rate_hz);
  const std::string profile = "RNG19_RFL8_SIG16_NIR16";
  nlohmann::json doc;
  doc["beam_intrinsics"] = {
      {"beam_altitude_angles", altitude},
      {"beam_azimuth_angles", azimuth},
      {"lidar_origin_to_beam_origin_mm", n_mm},
      {"beam_to_lidar_transform", {1, 0, 0, n_mm, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
  doc["lidar_intrinsics"] = {
      {"lidar_to_sensor_transform", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
  doc["imu_intrinsics"] = {
      {"imu_to_sensor_transform", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}};
  doc["lidar_data_format"] = {
      {"pixels_per_column", s.beams},
      {"columns_per_packet", kColumnsPerPacket},
      {"columns_per_frame", s.columns},
      {"pixel_shift_by_row", std::vector<int>(static_cast<size_t>(s.beams), 0)},
      {"column_window", {0, s.columns - 1}},
      {"udp_profile_lidar", profile},
      {"udp_profile_imu", "LEGACY"}};
  doc["config_params"] = {{"lidar_mode", mode},
                          {"udp_port_lidar", kLidarPort},
                          {"udp_port_imu", kImuPort},
                          {"udp_profile_lidar", profile}};
  doc["sensor_info"] = {{"prod_line", product_line(s.name)},
                        {"prod_sn", std::to_string(kSerial)},
                        {"initialization_id", kInitializationId},
                        {"status", "RUNNING"}};
  return doc.dump(2) + "\n";
}

void OusterPcapRecorder::add(const Scan& scan) {
  State& st = *state_;
  const config::SensorModel& s = st.sensor;
  if (scan.rows != s.beams || scan.cols != s.columns) {
    throw std::invalid_argument("a scan of " + std::to_string(scan.rows) + " x " +
                                std::to_string(scan.cols) + " for a sensor of " +
                                std::to_string(s.beams) + " x " + std::to_string(s.columns));
  }
  const ScanChannel* reflectivity = scan.channel("reflectivity");
  const ScanChannel* signal = scan.channel("intensity");
  if (signal == nullptr) signal = scan.channel("signal");
  const ScanChannel* nir = scan.channel("nir");
  // Column times from the scan where a column has a point, else from its place in the turn.
  const std::vector<std::optional<float>> offsets = scan.column_time_offsets_s();
  const double column_s = 1.0 / (static_cast<double>(s.columns) * st.rate_hz);
  std::vector<int64_t> column_ns(static_cast<size_t>(s.columns));
  for (int c = 0; c < s.columns; ++c) {
    const std::optional<float>& t = offsets[static_cast<size_t>(c)];
    const double seconds = t ? static_cast<double>(*t) : c * column_s;
    column_ns[static_cast<size_t>(c)] = scan.stamp_ns + std::llround(seconds * 1e9);
  }

  // Lidar packets and IMU samples go out in time order.
  const detail::OusterPacketLayout& layout = st.layout;
  size_t next_imu = 0;
  const auto send_imu_until = [&](int64_t time_ns) {
    for (; next_imu < scan.imu.size() && scan.imu[next_imu].stamp_ns <= time_ns; ++next_imu) {
      const ImuSample& sample = scan.imu[next_imu];
      // A sample at the instant where one sweep ends and the next begins may come with both.
      if (st.imu_written && sample.stamp_ns <= st.last_imu_stamp_ns) continue;
      uint8_t imu[kOusterImuPacketBytes] = {};
      for (size_t k = 0; k < 3; ++k)
        store_le_bytes(imu + 8 * k, static_cast<uint64_t>(sample.stamp_ns), 8);
      for (int k = 0; k < 3; ++k) {
        put_float(imu + 24 + 4 * k, sample.accel_mps2[k] / kStandardGravity);
        put_float(imu + 36 + 4 * k, sample.gyro_radps[k] * 180.0 / M_PI);
      }
      st.pcap.add(sample.stamp_ns, kImuPort, kImuPort, imu, kOusterImuPacketBytes);
      ++st.imu_packets;
      st.imu_written = true;
      st.last_imu_stamp_ns = sample.stamp_ns;
    }
  };

  for (int first = 0; first < s.columns; first += kColumnsPerPacket) {
    st.packet.assign(layout.packet_bytes, 0);
    uint8_t* p = st.packet.data();
    store_le_bytes(p, kLidarDataPacketType, 2);
    store_le_bytes(p + 2, st.frame_id, 2);
    store_le_bytes(p + 4, kInitializationId, 3);
    store_le_bytes(p + 7, kSerial, 5);
    int64_t sent_ns = 0;
    for (int k = 0; k < kColumnsPerPacket; ++k) {
      const int c = first + k;
      uint8_t* column = p + layout.header_bytes + static_cast<size_t>(k) * layout.column_bytes;
      if (c >= s.columns) {  // past the frame's last column: a column marked invalid
        store_le_bytes(column + 8, static_cast<uint64_t>(s.columns), 2);
        continue;
      }
      const int64_t t = column_ns[static_cast<size_t>(c)];
      sent_ns = t;
      store_le_bytes(column, static_cast<uint64_t>(t), 8);
      store_le_bytes(column + 8, static_cast<uint64_t>(c), 2);
      store_le_bytes(column + 10, 1, 2);  // status: valid
      for (int row = 0; row < s.beams; ++row) {
        const size_t i = scan.index(row, c);
        uint8_t* pixel =
            column + layout.column_header_bytes + static_cast<size_t>(row) * layout.pixel_bytes;
        const double range_mm = std::round(static_cast<double>(scan.range_m[i]) * 1000.0);
        if (scan.valid[i] && range_mm > 0.0 && range_mm <= kMaxRangeMm) {
          store_le_bytes(pixel, static_cast<uint32_t>(range_mm), 4);
        }
        if (reflectivity != nullptr) {
          const float v = reflectivity->values[i];
          pixel[4] = v > 0.0f ? static_cast<uint8_t>(std::min(255.0f, std::round(v))) : 0;
        }
        if (signal != nullptr) store_le_bytes(pixel + 6, clamp_u16(signal->values[i]), 2);
        if (nir != nullptr) store_le_bytes(pixel + 8, clamp_u16(nir->values[i]), 2);
      }
    }
    send_imu_until(sent_ns);
    st.pcap.add(sent_ns, kLidarPort, kLidarPort, st.packet.data(), st.packet.size());
    ++st.lidar_packets;
  }
  send_imu_until(std::numeric_limits<int64_t>::max());
  ++st.frame_id;  // wraps at 65,536 as the sensor's does
}

void OusterPcapRecorder::finish() { state_->pcap.finish(); }

}  // namespace featsense::slam
