#include "source_options.hpp"

#include "featsense/mapping/recording.hpp"

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
  return mapping::open_recording(input, config, meta_path, topic);
}

}  // namespace featsense::app
