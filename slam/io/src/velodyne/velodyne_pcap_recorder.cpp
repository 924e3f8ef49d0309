// Scans of a Velodyne's firing grid (velodyne_firing_geometry.hpp) -> the sensor's 1206-byte
// data packets (velodyne_model.hpp) in a pcap.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "featsense/slam/io/pcap_recorders.hpp"
#include "net/pcap_writer.hpp"
#include "ouster/byte_order.hpp"
#include "velodyne/velodyne_firing_geometry.hpp"

namespace featsense::slam {
namespace {

using detail::store_le_bytes;

constexpr uint16_t kDataPort = 2368;
constexpr size_t kTimeStampByte = 1200;
constexpr uint8_t kStrongestReturn = 0x37;
constexpr int64_t kHourUs = int64_t{3600} * 1000000;

}  // namespace

struct VelodynePcapRecorder::State {
  State(const std::string& path, VelodyneFiringGeometry g)
      : geometry(std::move(g)),
        column_ns(1e9 / (geometry.columns * geometry.sensor.rate_hz)),
        distance_unit_m(velodyne_distance_unit_m(geometry.model)),
        pcap(path) {}

  /// Writes one firing sequence, `scan`'s column `c` (nullptr: a firing without returns),
  /// made at `time_ns` by column `column` of the turn; sends the packet it completes.
  void fire(const Scan* scan, int c, int64_t column, int64_t time_ns);
  /// Fills the packet being written with firings without returns and sends it.
  void complete_packet();

  VelodyneFiringGeometry geometry;
  double column_ns;  ///< one firing sequence
  double distance_unit_m;
  detail::PcapWriter pcap;
  std::array<uint8_t, kVelodynePacketBytes> packet{};
  int firings = 0;  ///< in `packet` so far
  int64_t next_column = 0;
  int64_t next_time_ns = 0;  ///< when the firing after the last one is due
  uint64_t packets = 0;
};

void VelodynePcapRecorder::State::fire(const Scan* scan, int c, int64_t column, int64_t time_ns) {
  const int per_block = geometry.columns_per_block;
  const int per_packet = static_cast<int>(kVelodyneBlocks) * per_block;
  uint8_t* block = packet.data() + static_cast<size_t>(firings / per_block) * kVelodyneBlockBytes;
  const int sequence = firings % per_block;
  if (sequence == 0) {
    block[0] = 0xFF;  // the flag of the upper (only) bank, FF EE
    block[1] = 0xEE;
    store_le_bytes(block + 2, geometry.azimuth_centideg(column), 2);
  }
  if (firings == 0) {
    // Microseconds past the full hour of the sensor's clock, of the packet's first firing.
    const int64_t us = (time_ns + 500) / 1000;
    store_le_bytes(packet.data() + kTimeStampByte, static_cast<uint64_t>(us % kHourUs), 4);
  }
  if (scan != nullptr) {
    const ScanChannel* reflectivity = scan->intensity();  // reflectivity where there is one
    const size_t slots_per_sequence = kVelodyneSlots / static_cast<size_t>(per_block);
    for (int row = 0; row < scan->rows; ++row) {
      const size_t i = scan->index(row, c);
      const size_t slot = static_cast<size_t>(sequence) * slots_per_sequence +
                          static_cast<size_t>(geometry.laser_of_row[static_cast<size_t>(row)]);
      uint8_t* ret = block + 4 + slot * 3;
      const double units = std::round(scan->range_m[i] / distance_unit_m);
      if (!scan->valid[i] || units < 1.0 || units > 65535.0) continue;  // 0: no return
      store_le_bytes(ret, static_cast<uint64_t>(units), 2);
      const float v = reflectivity != nullptr ? reflectivity->values[i] : 0.0f;
      ret[2] = v > 0.0f ? static_cast<uint8_t>(std::min(255.0f, std::round(v))) : 0;
    }
  }
  next_column = column + 1;
  next_time_ns = time_ns + std::llround(column_ns);
  if (++firings < per_packet) return;
  // Sent once its last firing was measured.
  packet[kVelodyneReturnModeByte] = kStrongestReturn;
  // The models written all have one (velodyne_firing_geometry refuses the HDL-64E).
  packet[kVelodyneProductIdByte] = velodyne_product_id(geometry.model).value_or(0);
  pcap.add(time_ns, kDataPort, kDataPort, packet.data(), packet.size());
  ++packets;
  packet.fill(0);
  firings = 0;
}

void VelodynePcapRecorder::State::complete_packet() {
  while (firings > 0) fire(nullptr, 0, next_column, next_time_ns);
}

VelodynePcapRecorder::VelodynePcapRecorder(const std::string& pcap_path, const std::string& preset,
                                           double rate_hz) {
  VelodyneFiringGeometry geometry = velodyne_firing_geometry(preset, rate_hz);
  state_ = std::make_unique<State>(pcap_path, std::move(geometry));
}

VelodynePcapRecorder::~VelodynePcapRecorder() = default;

uint64_t VelodynePcapRecorder::packets() const { return state_->packets; }

void VelodynePcapRecorder::add(const Scan& scan) {
  State& st = *state_;
  const config::SensorModel& s = st.geometry.sensor;
  if (scan.rows != s.beams || scan.cols != s.columns) {
    throw std::invalid_argument("a scan of " + std::to_string(scan.rows) + " x " +
                                std::to_string(scan.cols) + " for a " + s.name + " firing " +
                                std::to_string(s.beams) + " x " + std::to_string(s.columns));
  }
  // Column times from the scan where a column has a point, else from its place in the turn.
  const std::vector<std::optional<float>> offsets = scan.column_time_offsets_s();
  const auto time_of = [&](int c) {
    const std::optional<float>& t = offsets[static_cast<size_t>(c)];
    return scan.stamp_ns +
           (t ? std::llround(static_cast<double>(*t) * 1e9) : std::llround(c * st.column_ns));
  };
  // A packet's firings follow each other at the model's pace: a scan that does not continue
  // the last one without a gap starts a packet of its own.
  if (st.firings > 0 &&
      std::abs(static_cast<double>(time_of(0) - st.next_time_ns)) > 0.5 * st.column_ns) {
    st.complete_packet();
  }
  for (int c = 0; c < s.columns; ++c) st.fire(&scan, c, c, time_of(c));
}

void VelodynePcapRecorder::finish() {
  state_->complete_packet();
  state_->pcap.finish();
}

}  // namespace featsense::slam
