#pragma once
/// Scans written as the packets a sensor sends them, into a pcap capture of an Ethernet link:
/// `featsense simulate --format ouster-pcap|velodyne-pcap` uses these, so that long recordings
/// with ground truth exist in the sensors' own formats for `featsense replay`, `featsense live`
/// and the pcap readers, which read them back as they read a real sensor's captures.

#include <cstdint>
#include <memory>
#include <string>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/scan_writers.hpp"  // WriteError
#include "featsense/slam/scan.hpp"

namespace featsense::slam {

/// An Ouster sensor of firmware 2.x in the RNG19_RFL8_SIG16_NIR16 profile (1 mm ranges):
/// lidar packets of 16 columns on UDP 7502 and 48-byte IMU packets on 7503, and the metadata
/// JSON (nested layout) that describes them. The scans must be organized as
/// `featsense simulate` makes them (slam/sim beam_geometry): row r of column c looks along
/// azimuth -2 pi c / columns + azimuth_offset_rad[r] at elevation_rad[r], from a beam origin
/// beam_origin_offset_m out along the column's azimuth, range_m measured from the lidar
/// origin; the metadata then says exactly that (no destaggering shifts, an identity
/// lidar_to_sensor_transform, since the scans' frame is the lidar's own).
class OusterPcapRecorder {
 public:
  /// Throws ConfigError where Ouster's format cannot describe `sensor` (a rate that is no
  /// whole number of revolutions per second, more than 65,535 columns or 4,095 beams), and
  /// WriteError where the pcap cannot be created.
  OusterPcapRecorder(const std::string& pcap_path, config::SensorModel sensor);
  ~OusterPcapRecorder();
  OusterPcapRecorder(const OusterPcapRecorder&) = delete;
  OusterPcapRecorder& operator=(const OusterPcapRecorder&) = delete;

  /// The metadata JSON of the sensor that sent the packets, for the file beside the pcap.
  std::string metadata_json() const;
  /// Writes one revolution: its columns as lidar packets, each sent when its last column was
  /// measured, and its IMU samples as IMU packets at their times. Throws std::invalid_argument
  /// for a scan of another size than the sensor's, WriteError where writing fails.
  void add(const Scan& scan);
  /// Closes the capture. Throws WriteError where writing failed.
  void finish();

  uint64_t lidar_packets() const;
  uint64_t imu_packets() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace featsense::slam
