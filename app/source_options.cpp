#include "source_options.hpp"

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "featsense/slam/sim/box_room_source.hpp"

namespace featsense::app {

void InputOptions::add_to(CLI::App& command, bool input_optional) {
  auto* positional = command.add_option(
      "INPUT", input,
      "Recording: Ouster or Velodyne pcap, ROS1 bag, ROS 2 bag (folder or .db3), MCAP file, "
      "PCD or PLY file, or a folder of KITTI .bin / PCD / PLY scans or of `featsense "
      "simulate`");
  if (input_optional) {
    positional->description(positional->get_description() +
                            " (default: a built-in example, an analytic box room)");
  } else {
    positional->required();
  }
  command.add_option("--meta", meta_path, "Ouster metadata JSON (default: found beside the pcap)")
      ->check(CLI::ExistingFile);
  command.add_option(
      "--topic", topic,
      "Bag or MCAP topic to read (default: the one scan topic; `featsense info` lists them)");
}

std::unique_ptr<slam::ScanSource> InputOptions::open(const config::Config& config) const {
  if (input.empty()) {
    slam::BoxRoomSettings settings = slam::default_box_room();
    if (config.sensor.preset != "auto") {
      settings.sensor = config::sensor_preset(config.sensor.preset);
    }
    return slam::with_range_limits(slam::make_box_room_source(settings),
                                   config.sensor.min_range_m.value_or(settings.sensor.min_range_m),
                                   config.sensor.max_range_m.value_or(settings.sensor.max_range_m));
  }
  slam::SourceOptions options;
  options.meta_path = meta_path;
  options.topic = topic;
  options.sensor_preset = config.sensor.preset;
  options.min_range_m = config.sensor.min_range_m;
  options.max_range_m = config.sensor.max_range_m;
  options.times_from_azimuth = config.sensor.times_from_azimuth;
  options.velodyne_calibration = config.sensor.calibration;
  options.scan_cut_deg = config.sensor.scan_cut_deg;
  options.imu = config.sensor.imu;
  options.imu_topic = config.sensor.imu_topic;
  options.imu_rotation_deg = config.sensor.imu_rotation_deg;
  return slam::open_scan_source(input, options);
}

}  // namespace featsense::app
