#pragma once
/// Velodyne packets into scans: the returns of each packet decoded, a scan cut where the
/// firings' azimuth passes the cut angle, and organized into the Scan layout (scan.hpp):
/// one row per laser, highest first; columns by the firing's azimuth counted clockwise from
/// the cut, so that time grows with the column.

#include <cstdint>
#include <deque>
#include <optional>
#include <utility>
#include <vector>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/scan.hpp"
#include "velodyne/velodyne_packet.hpp"

namespace featsense::slam {

struct VelodyneScanSettings {
  double cut_angle_rad = M_PI;  ///< azimuth (clockwise from +x) where one scan ends
  int columns = 1800;           ///< per turn
};

class VelodyneScanAssembler {
 public:
  VelodyneScanAssembler(VelodynePacketDecoder decoder, const VelodyneCalibration& calibration,
                        VelodyneScanSettings settings);

  /// Adds one packet of kVelodynePacketBytes received at `stamp_ns` (a receive or capture
  /// time). Scans that it completes are queued for take().
  ///
  /// Times: a packet's own time stamp (microseconds past the hour of the sensor's clock)
  /// spaces the firings exactly, while receive times come in bursts (a driver that buffers
  /// packets stamps them milliseconds apart, then microseconds). So a packet's time is its
  /// own stamp plus the clocks' offset, estimated as the smallest receive-minus-sensor time
  /// of the last few thousand packets (a packet never arrives before it was sent).
  void add_packet(const uint8_t* packet, int64_t stamp_ns);
  /// Queues the scan being assembled, if it holds any return (at the end of the input).
  void flush();
  /// The next completed scan, in order, numbered from 0.
  std::optional<Scan> take();

  /// Packets in dual-return mode: each cell keeps the farther of its two returns (the
  /// last return, for a surface behind a thin or transparent one).
  uint64_t dual_return_packets() const { return dual_packets_; }
  uint64_t collisions() const { return collisions_; }
  const VelodynePacketDecoder& decoder() const { return decoder_; }

 private:
  void start_scan();
  void finish_scan();
  int column_of(double firing_azimuth) const;
  int64_t packet_time_ns(const uint8_t* packet, int64_t stamp_ns);

  VelodynePacketDecoder decoder_;
  VelodyneScanSettings settings_;
  std::vector<int> row_of_laser_;
  int rows_ = 0;
  double cut_centideg_ = 0.0;
  std::vector<VelodyneReturn> returns_;  ///< reused per packet
  std::optional<Scan> scan_;             ///< being assembled
  std::vector<int64_t> point_time_ns_;   ///< absolute, of each cell of scan_
  int64_t first_time_ns_ = 0;
  std::optional<double> last_phase_;  ///< azimuth past the cut of the last firing, centideg
  std::deque<Scan> done_;
  std::optional<int64_t> last_sensor_us_;  ///< unwrapped past the hour, for the next packet
  int64_t sensor_hours_us_ = 0;            ///< whole hours added by wraps
  uint64_t packets_ = 0;
  /// (packet number, receive - sensor time) with increasing offsets: the window's minimum
  /// at the front.
  std::deque<std::pair<uint64_t, int64_t>> offsets_;
  uint64_t sequence_ = 0;
  uint64_t dual_packets_ = 0;
  uint64_t collisions_ = 0;
};

/// The sensor model of a Velodyne stream: the preset's columns, rate and range limits, with
/// the calibration's elevations (rows highest first) and azimuth offsets.
config::SensorModel velodyne_sensor_model(config::SensorModel preset,
                                          const VelodyneCalibration& calibration);

}  // namespace featsense::slam
