#include "live_input.hpp"

#include <cstdio>
#include <fstream>

#include "featsense/mapping/recording.hpp"
#include "ouster_metadata_fetch.hpp"

namespace featsense::app {
namespace {

/// The Ouster metadata's file: `meta_path`, else the sensor's answer saved into the output
/// folder (kept there: the record of the sensor the run was made with).
std::optional<std::string> metadata_path(const LiveInputOptions& options,
                                         const std::optional<std::string>& meta_path,
                                         const std::filesystem::path& output) {
  if (meta_path || !options.sensor_address || options.sensor != "ouster") return meta_path;
  const std::string json = fetch_ouster_metadata(*options.sensor_address);
  std::filesystem::create_directories(output);
  const std::filesystem::path path = output / "sensor_metadata.json";
  std::ofstream file(path, std::ios::binary);
  file << json;
  if (!file) throw slam::InputError(path.string() + ": cannot write the sensor's metadata");
  return path.string();
}

}  // namespace

void LiveInputOptions::add_to(CLI::App& command, bool required) {
  CLI::Option* option =
      command
          .add_option("--sensor", sensor,
                      required ? "ouster or velodyne"
                               : "ouster or velodyne: take the scans from this sensor on the "
                                 "network (as `featsense live`) in place of a recording")
          ->check(CLI::IsMember({"ouster", "velodyne"}));
  if (required) option->required();
  command.add_option("--sensor-address", sensor_address,
                     "Ouster without --meta: the sensor's address (host or host:port); its "
                     "metadata is fetched from its HTTP API and kept as "
                     "OUT/sensor_metadata.json");
  command
      .add_option("--host", live.host, "Local IPv4 address to listen on (0.0.0.0: every interface)")
      ->capture_default_str();
  command
      .add_option("--lidar-port", live.lidar_port,
                  "Lidar packets' UDP port (Ouster: the metadata's, 7502; Velodyne: 2368)")
      ->check(CLI::Range(1, 65535));
  command
      .add_option("--imu-port", live.imu_port,
                  "Ouster IMU packets' UDP port (the metadata's, 7503)")
      ->check(CLI::Range(1, 65535));
  command
      .add_option("--idle-timeout", live.idle_timeout_s,
                  "End the run after this many seconds without a packet (0: only Ctrl+C)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

std::unique_ptr<slam::ScanSource> LiveInputOptions::open(
    const config::Config& config, const std::optional<std::string>& meta_path,
    const std::filesystem::path& output, const StopSignal& stop, bool quiet,
    const std::string& stop_text) {
  live.sensor = sensor == "velodyne" ? slam::LiveSensor::kVelodyne : slam::LiveSensor::kOuster;
  live.stop_requested = [&stop] { return stop.requested(); };
  live.on_listening = [quiet, stop_text](const std::string& address) {
    if (quiet) return;
    std::printf("listening on %s; %s\n", address.c_str(), stop_text.c_str());
    std::fflush(stdout);
  };
  return slam::open_live_source(
      live, mapping::source_options(config, metadata_path(*this, meta_path, output), std::nullopt));
}

}  // namespace featsense::app
