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

/// The sensor that `featsense simulate` fires for a Velodyne whose packets
/// VelodynePcapRecorder writes: Velodyne preset `preset` (hdl32, vlp32c or vlp16) turning
/// `rate_hz` times per second (0: the preset's rate). One column per firing sequence
/// (round(1e6 / (rate_hz * sequence_us)): 2170 for the HDL-32E at 10 Hz, 1808 for the VLP-32C
/// and the VLP-16, whose revolutions are whole blocks of two sequences), so the simulated
/// motor turns at exactly rate_hz. Rows are the lasers of the model's built-in table (which
/// the reader uses without sensor.calibration) by elevation, highest first, as the reader
/// orders them. Each row's azimuth offset holds the laser's rot_correction, the turn that
/// the reader adds for the laser's slot in its firing, and column 0's azimuth: the reader's
/// default scan cut (sensor.scan_cut_deg, 180 deg), so that each simulated revolution reads
/// back as one scan, plus half a column, so that no firing lies on the edge of a column of
/// the reader's grid. No beam origin offset. Throws ConfigError for another preset, for the
/// HDL-64E and VLS-128, and for a rate outside 5 to 20 Hz.
config::SensorModel velodyne_firing_sensor(const std::string& preset, double rate_hz = 0.0);

/// A Velodyne HDL-32E, VLP-32C or VLP-16 in strongest-return mode: 1206-byte data packets on
/// UDP 2368, each of 12 blocks (one firing sequence each, two on the VLP-16) with the block's
/// azimuth in 0.01 deg, distances in the model's unit (2 mm, 4 mm on the VLP-32C) and
/// reflectivity bytes; the packet's time stamp (microseconds past the hour) is its first
/// firing's, and it is sent when its last firing was measured. No position packets. The
/// scans must be those of velodyne_firing_sensor(preset, rate_hz), simulated frame after
/// frame: packets run on across scans, as the sensor's do.
///
/// The reader decodes them (without sensor.calibration) to the simulated points within the
/// format's resolution: half a distance unit along the beam, and the 0.01 deg block azimuths
/// that it interpolates for each laser's slot (at most 1 + the slot's fraction of a step, in
/// 0.01 deg). Where the reader departs from the firings, so do its points: on the VLP-32C it
/// gives the last block of each packet no turn (as the reference decoder does), which turns
/// that block's returns back by up to 1.3 firing steps (0.26 deg at 10 Hz); it dates a
/// packet by its capture, so its times come one packet's span late (0.51 ms on the HDL-32E,
/// 0.61 ms on the VLP-32C at 10 Hz); and it keeps one firing per column of the preset, so at
/// 10 Hz it drops the VLP-16 firings (about a dozen a turn) that share one of its 1800.
class VelodynePcapRecorder {
 public:
  /// Throws ConfigError as velodyne_firing_sensor does, and WriteError where the pcap cannot
  /// be created.
  VelodynePcapRecorder(const std::string& pcap_path, const std::string& preset,
                       double rate_hz = 0.0);
  ~VelodynePcapRecorder();
  VelodynePcapRecorder(const VelodynePcapRecorder&) = delete;
  VelodynePcapRecorder& operator=(const VelodynePcapRecorder&) = delete;

  /// Writes one revolution as firings: column by column, packet by packet, at the columns'
  /// times (the scan's, else their places in the turn). A scan that does not follow the last
  /// one without a gap starts a packet of its own, the one before filled with firings that
  /// saw nothing. Throws std::invalid_argument for a scan of another size than the firing
  /// sensor's, WriteError where writing fails.
  void add(const Scan& scan);
  /// Fills the last packet with firings that saw nothing, sends it and closes the capture.
  /// Throws WriteError where writing failed.
  void finish();

  uint64_t packets() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace featsense::slam
