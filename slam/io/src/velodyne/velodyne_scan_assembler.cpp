#include "velodyne/velodyne_scan_assembler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace featsense::slam {
namespace {

/// Packets over which the clocks' offset is the smallest seen (about half a second to three
/// seconds of packets, depending on the model): long enough to include a packet that came
/// without delay, short enough to follow the clocks' drift.
constexpr uint64_t kOffsetWindowPackets = 4096;
constexpr int64_t kHourUs = int64_t{3600} * 1000000;

/// Laser numbers sorted by elevation, highest first: the scan's rows.
std::vector<size_t> lasers_highest_first(const VelodyneCalibration& calibration) {
  std::vector<size_t> order(calibration.lasers.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return calibration.lasers[a].vert_rad > calibration.lasers[b].vert_rad;
  });
  return order;
}

}  // namespace

VelodyneScanAssembler::VelodyneScanAssembler(VelodynePacketDecoder decoder,
                                             const VelodyneCalibration& calibration,
                                             VelodyneScanSettings settings)
    : decoder_(std::move(decoder)), settings_(settings) {
  const std::vector<size_t> order = lasers_highest_first(calibration);
  rows_ = static_cast<int>(order.size());
  row_of_laser_.assign(order.size(), 0);
  for (size_t row = 0; row < order.size(); ++row) row_of_laser_[order[row]] = static_cast<int>(row);
  cut_centideg_ = std::fmod(settings_.cut_angle_rad * 18000.0 / M_PI, 36000.0);
  if (cut_centideg_ < 0.0) cut_centideg_ += 36000.0;
}

int VelodyneScanAssembler::column_of(double firing_azimuth) const {
  double phase = std::fmod(firing_azimuth - cut_centideg_ + 36000.0, 36000.0);
  const int column = static_cast<int>(phase / 36000.0 * settings_.columns);
  return std::clamp(column, 0, settings_.columns - 1);
}

void VelodyneScanAssembler::start_scan() {
  scan_ = Scan::allocate(rows_, settings_.columns);
  scan_->add_channel("intensity");
  point_time_ns_.assign(scan_->size(), 0);
  first_time_ns_ = std::numeric_limits<int64_t>::max();
}

void VelodyneScanAssembler::finish_scan() {
  if (!scan_) return;
  if (scan_->valid_count() > 0) {
    // The stamp is the scan's first firing; offsets count from it (scan.hpp).
    scan_->stamp_ns = first_time_ns_;
    for (size_t i = 0; i < scan_->size(); ++i) {
      if (scan_->valid[i]) {
        scan_->time_offset_s[i] = static_cast<float>(1e-9 * (point_time_ns_[i] - first_time_ns_));
      }
    }
    scan_->sequence = sequence_++;
    done_.push_back(std::move(*scan_));
  }
  scan_.reset();
}

int64_t VelodyneScanAssembler::packet_time_ns(const uint8_t* packet, int64_t stamp_ns) {
  int64_t sensor_us =
      static_cast<int64_t>(packet[1200] | (packet[1201] << 8) | (packet[1202] << 16) |
                           (static_cast<uint32_t>(packet[1203]) << 24));
  if (sensor_us >= kHourUs) return stamp_ns;  // no valid sensor time: the receive time
  sensor_us += sensor_hours_us_;
  if (last_sensor_us_ && sensor_us < *last_sensor_us_ - kHourUs / 2) {
    sensor_hours_us_ += kHourUs;  // the sensor's clock passed the full hour
    sensor_us += kHourUs;
  }
  last_sensor_us_ = sensor_us;
  const int64_t offset = stamp_ns - sensor_us * 1000;
  const uint64_t number = packets_++;
  while (!offsets_.empty() && offsets_.back().second >= offset) offsets_.pop_back();
  offsets_.emplace_back(number, offset);
  while (offsets_.front().first + kOffsetWindowPackets <= number) offsets_.pop_front();
  return sensor_us * 1000 + offsets_.front().second;
}

void VelodyneScanAssembler::add_packet(const uint8_t* packet, int64_t stamp_ns) {
  if (VelodynePacketDecoder::dual_return(packet)) ++dual_packets_;
  const int64_t packet_ns = packet_time_ns(packet, stamp_ns);
  returns_.clear();
  decoder_.decode(packet, returns_);
  // Firings whose phase past the cut falls back start a new scan: the turn passed the cut.
  int current_block = -1;
  for (const VelodyneReturn& r : returns_) {
    if (r.block != current_block) {
      current_block = r.block;
      const double phase = std::fmod(r.firing_azimuth - cut_centideg_ + 36000.0, 36000.0);
      if (last_phase_ && phase < *last_phase_) finish_scan();
      last_phase_ = phase;
    }
    if (!scan_) start_scan();
    const int row = row_of_laser_[r.laser];
    const size_t i = scan_->index(row, column_of(r.firing_azimuth));
    const int64_t time_ns = packet_ns + static_cast<int64_t>(std::llround(r.time_offset_s * 1e9));
    if (scan_->valid[i]) {
      ++collisions_;
      // Dual returns share a cell: the farther (last) return stays. Otherwise two firings
      // fell into one column: the first stays.
      if (!(VelodynePacketDecoder::dual_return(packet) && r.distance_m > scan_->range_m[i])) {
        continue;
      }
    }
    scan_->xyz[i] = r.xyz;
    scan_->range_m[i] = r.distance_m;
    scan_->valid[i] = 1;
    scan_->channels.front().values[i] = r.reflectivity;
    point_time_ns_[i] = time_ns;
    first_time_ns_ = std::min(first_time_ns_, time_ns);
  }
}

void VelodyneScanAssembler::flush() { finish_scan(); }

std::optional<Scan> VelodyneScanAssembler::take() {
  if (done_.empty()) return std::nullopt;
  Scan scan = std::move(done_.front());
  done_.pop_front();
  return scan;
}

config::SensorModel velodyne_sensor_model(config::SensorModel preset,
                                          const VelodyneCalibration& calibration) {
  const std::vector<size_t> order = lasers_highest_first(calibration);
  preset.beams = static_cast<int>(order.size());
  preset.elevation_rad.clear();
  preset.azimuth_offset_rad.clear();
  for (size_t laser : order) {
    preset.elevation_rad.push_back(calibration.lasers[laser].vert_rad);
    // A laser whose rot_correction is positive fires before (anticlockwise of) its firing's
    // azimuth.
    preset.azimuth_offset_rad.push_back(-calibration.lasers[laser].rot_rad);
  }
  return preset;
}

}  // namespace featsense::slam
