#include "featsense/mapping/recording.hpp"

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/box_room_source.hpp"

namespace featsense::mapping {

slam::SourceOptions source_options(const config::Config& config,
                                   const std::optional<std::string>& meta_path,
                                   const std::optional<std::string>& topic) {
  slam::SourceOptions options;
  options.meta_path = meta_path;
  options.topic = topic;
  options.sensor_preset = config.sensor.preset;
  options.min_range_m = config.sensor.min_range_m;
  options.max_range_m = config.sensor.max_range_m;
  options.self_box = config.sensor.self_box;
  options.times_from_azimuth = config.sensor.times_from_azimuth;
  options.velodyne_calibration = config.sensor.calibration;
  options.scan_cut_deg = config.sensor.scan_cut_deg;
  options.imu = config.sensor.imu;
  options.imu_topic = config.sensor.imu_topic;
  options.imu_rotation_deg = config.sensor.imu_rotation_deg;
  return options;
}

std::unique_ptr<slam::ScanSource> open_recording(const std::string& path,
                                                 const config::Config& config,
                                                 const std::optional<std::string>& meta_path,
                                                 const std::optional<std::string>& topic) {
  if (!path.empty()) return slam::open_scan_source(path, source_options(config, meta_path, topic));
  slam::BoxRoomSettings settings = slam::default_box_room();
  if (config.sensor.preset != "auto") settings.sensor = config::sensor_preset(config.sensor.preset);
  return slam::with_range_limits(slam::make_box_room_source(settings),
                                 config.sensor.min_range_m.value_or(settings.sensor.min_range_m),
                                 config.sensor.max_range_m.value_or(settings.sensor.max_range_m),
                                 config.sensor.self_box);
}

}  // namespace featsense::mapping
