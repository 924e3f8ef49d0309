// featsense live: maps a sensor on the network as it sends, until Ctrl+C or a silence, with
// everything `featsense map` writes.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "featsense/mapping/recording.hpp"
#include "featsense/slam/io/live_source.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "map_job.hpp"
#include "map_outputs.hpp"
#include "ouster_metadata_fetch.hpp"
#include "stop_signal.hpp"

namespace featsense::app {
namespace {

struct LiveCommandOptions {
  std::string sensor;
  slam::LiveOptions live;
  std::optional<std::string> meta_path;
  std::optional<std::string> sensor_address;  ///< Ouster: where to fetch the metadata from
  MapOptions map;
};

/// The Ouster metadata's file: --meta, else the sensor's answer saved into the output folder
/// (kept there: the record of the sensor the map was made with).
std::optional<std::string> metadata_path(const LiveCommandOptions& options) {
  if (options.meta_path || !options.sensor_address || options.sensor != "ouster") {
    return options.meta_path;
  }
  const std::string json = fetch_ouster_metadata(*options.sensor_address);
  const std::filesystem::path out(options.map.output);
  std::filesystem::create_directories(out);
  const std::filesystem::path path = out / "sensor_metadata.json";
  std::ofstream file(path, std::ios::binary);
  file << json;
  if (!file) throw slam::InputError(path.string() + ": cannot write the sensor's metadata");
  return path.string();
}

void run_live(LiveCommandOptions& options, const CliContext& context) {
  options.live.sensor =
      options.sensor == "velodyne" ? slam::LiveSensor::kVelodyne : slam::LiveSensor::kOuster;
  const config::Config config = map_config(options.map, context);
  options.map.real_time = true;
  const StopSignal stop_signal(StopSignal::kMapMessage);
  options.live.stop_requested = [&stop_signal] { return stop_signal.requested(); };
  options.live.on_listening = [&context](const std::string& address) {
    if (context.quiet) return;
    std::printf("listening on %s; Ctrl+C ends the run and writes the map\n", address.c_str());
    std::fflush(stdout);
  };
  std::unique_ptr<slam::ScanSource> source = slam::open_live_source(
      options.live, mapping::source_options(config, metadata_path(options), std::nullopt));
  // A dry run with a known path and surface (a simulated recording replayed) is evaluated as
  // `map` evaluates one: the estimate aligned to the truth.
  std::optional<KnownTrajectory> truth;
  if (options.map.reference_trajectory) {
    truth = KnownTrajectory{slam::read_trajectory(*options.map.reference_trajectory, "auto", {}),
                            false};
  }
  const MeshReferences references = find_mesh_references("", options.map.reference);
  // No second pass after loop closures: what the sensor sent cannot be read again.
  try {
    map_recording(*source, std::nullopt, truth, options.map, config, references, context, {},
                  &stop_signal);
  } catch (const Interrupted&) {
    if (!stop_signal.requested()) throw;  // Ctrl+C after scans: handled below
  } catch (const std::runtime_error&) {
    // Stopped before a scan came: say where nothing came from.
    if (stop_signal.requested() && source->stats().frames_read == 0) {
      throw slam::InputError(source->info().path +
                             ": no scan came before the stop (is the "
                             "sensor sending there? see --host, --lidar-port)");
    }
    throw;
  }
  if (stop_signal.requested()) {
    // Ctrl+C is how a live run ends: the map, the poses and the report are written.
    if (!context.quiet) {
      std::printf("stopped: the map, the poses and the report are in %s\n",
                  options.map.output.c_str());
    }
  }
}

}  // namespace

Command register_live(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<LiveCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "live",
      "Map a sensor on the network as it sends (Ouster or Velodyne UDP packets), until Ctrl+C "
      "or --idle-timeout: the TSDF map, the poses and a report, as `featsense map` writes them");
  command->add_option("--sensor", options->sensor, "ouster or velodyne")
      ->required()
      ->check(CLI::IsMember({"ouster", "velodyne"}));
  command->add_option("-o,--output", options->map.output, "Output folder")->required();
  command
      ->add_option("--meta", options->meta_path,
                   "Ouster: the sensor's metadata JSON (as the sensor's HTTP API serves it at "
                   "/api/v1/sensor/metadata, or a recording's)")
      ->check(CLI::ExistingFile);
  command->add_option("--sensor-address", options->sensor_address,
                      "Ouster without --meta: the sensor's address (host or host:port); its "
                      "metadata is fetched from its HTTP API and kept as OUT/sensor_metadata.json");
  command
      ->add_option("--host", options->live.host,
                   "Local IPv4 address to listen on (0.0.0.0: every interface)")
      ->capture_default_str();
  command
      ->add_option("--lidar-port", options->live.lidar_port,
                   "Lidar packets' UDP port (Ouster: the metadata's, 7502; Velodyne: 2368)")
      ->check(CLI::Range(1, 65535));
  command
      ->add_option("--imu-port", options->live.imu_port,
                   "Ouster IMU packets' UDP port (the metadata's, 7503)")
      ->check(CLI::Range(1, 65535));
  command
      ->add_option("--idle-timeout", options->live.idle_timeout_s,
                   "End the run after this many seconds without a packet (0: only Ctrl+C)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      ->add_option("--reference-trajectory", options->map.reference_trajectory,
                   "A dry run's true path (TUM or KITTI), to compare the poses with in "
                   "report.json (a simulated recording's gt_trajectory.tum)")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--reference", options->map.reference,
                   "A dry run's true surface, to evaluate the mesh against (gt_mesh.ply)")
      ->check(CLI::ExistingFile);
  add_config_option(*command, kBackendOption, options->map.backend);
  add_map_output_flags(*command, options->map);
  return {command, [options, &context] { run_live(*options, context); }};
}

}  // namespace featsense::app
