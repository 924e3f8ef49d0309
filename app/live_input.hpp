#pragma once
// A sensor on the network as the input of a command (`featsense live`, `featsense localize
// --sensor`): the options that say which sensor and where it sends, and the source they open.

#include <CLI/CLI.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "featsense/config/config.hpp"
#include "featsense/slam/io/live_source.hpp"
#include "featsense/slam/scan_source.hpp"
#include "stop_signal.hpp"

namespace featsense::app {

struct LiveInputOptions {
  std::string sensor;  ///< "ouster" or "velodyne"; empty: no sensor (a recording is read)
  slam::LiveOptions live;
  std::optional<std::string> sensor_address;  ///< Ouster: where to fetch the metadata from

  /// Adds --sensor (required when `required`), --sensor-address, --host, --lidar-port,
  /// --imu-port and --idle-timeout to `command`. --meta is the command's own.
  void add_to(CLI::App& command, bool required);

  /// Listens for the sensor's packets until `stop` or the idle timeout ends the input. The
  /// Ouster metadata is `meta_path`, else the sensor's answer from --sensor-address, kept as
  /// `output`/sensor_metadata.json. Prints the address listened on unless `quiet`. Throws
  /// slam::InputError.
  std::unique_ptr<slam::ScanSource> open(const config::Config& config,
                                         const std::optional<std::string>& meta_path,
                                         const std::filesystem::path& output,
                                         const StopSignal& stop, bool quiet,
                                         const std::string& stop_text);
};

}  // namespace featsense::app
