#pragma once
/// Opening a recording of any supported format, detected from its content.

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "featsense/config/config.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {

struct SourceOptions {
  std::optional<std::string> meta_path;  ///< Ouster metadata JSON (else found beside the pcap)
  std::optional<std::string> topic;      ///< ROS bag topic (else the one scan topic there is)
  std::string sensor_preset = config::SensorConfig{}.preset;  ///< config key sensor.preset
  std::optional<double> min_range_m;  ///< config key sensor.min_range (else the sensor's)
  std::optional<double> max_range_m;  ///< config key sensor.max_range (else the sensor's)
  /// Config key sensor.self_box: returns inside this box of the sensor frame are dropped.
  std::optional<std::array<double, 6>> self_box;
  /// Config key sensor.times_from_azimuth: clouds without a time field get per-point times
  /// from their points' azimuths (azimuth_times.hpp).
  bool times_from_azimuth = config::SensorConfig{}.times_from_azimuth;
  /// Config key sensor.calibration: a Velodyne calibration YAML (else the model's built-in
  /// laser table).
  std::optional<std::string> velodyne_calibration;
  /// Config key sensor.scan_cut_deg: the azimuth (degrees clockwise from +x) where packet
  /// streams (Velodyne) are cut into scans.
  double scan_cut_deg = config::SensorConfig{}.scan_cut_deg;
  /// Config key sensor.imu: deliver the IMU's samples with each scan (Scan::imu) where the
  /// input has them.
  bool imu = config::SensorConfig{}.imu;
  /// Config key sensor.imu_topic: a bag's IMU topic (else the one sensor_msgs/Imu topic).
  std::optional<std::string> imu_topic;
  /// Config key sensor.imu_rotation: roll, pitch, yaw (degrees) from the IMU frame into the
  /// sensor frame, for IMU messages that do not carry it (sensor_msgs/Imu).
  std::array<double, 3> imu_rotation_deg = config::SensorConfig{}.imu_rotation_deg;
};

/// Wraps `source` so that returns closer than min_m or farther than max_m (metres from the
/// sensor), returns inside `self_box` ([x_min, y_min, z_min, x_max, y_max, z_max], sensor
/// frame) and non-finite points are invalid in every scan it hands out.
std::unique_ptr<ScanSource> with_range_limits(
    std::unique_ptr<ScanSource> source, double min_m, double max_m,
    const std::optional<std::array<double, 6>>& self_box = std::nullopt);

/// Wraps `source` with the range limits and self box of `options` (else the sensor's limits).
std::unique_ptr<ScanSource> with_range_limits(std::unique_ptr<ScanSource> source,
                                              const SourceOptions& options);

/// Opens a recording, detecting its format from the content: an Ouster pcap, a ROS1 bag, a
/// ROS 2 bag (a folder holding metadata.yaml, or one .db3), an MCAP file, a PCD or PLY
/// file, or a folder of KITTI .bin / PCD / PLY scans or of `featsense simulate`.
/// Returned scans already have the range limits applied. Throws InputError.
std::unique_ptr<ScanSource> open_scan_source(const std::string& input,
                                             const SourceOptions& options = {});

}  // namespace featsense::slam
