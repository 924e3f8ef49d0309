// featsense live: maps a sensor on the network as it sends, until Ctrl+C or a silence, with
// everything `featsense map` writes.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "commands.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "live_input.hpp"
#include "live_view.hpp"
#include "map_job.hpp"
#include "map_outputs.hpp"
#include "stop_signal.hpp"
#include "view_server.hpp"

namespace featsense::app {
namespace {

struct LiveCommandOptions {
  LiveInputOptions sensor;
  std::optional<std::string> meta_path;
  MapOptions map;
  bool view = false;  ///< the map in the browser while it is made
  std::string view_host = "127.0.0.1";
  int view_port = 8765;
  double view_refresh_s = 1.0;
  size_t view_max_chunks = mapping::MapPreviewSettings{}.max_chunks;
  std::string three_folder = kThreeJsFolder;
};

/// The output folder's own name, for the page's title.
std::string folder_name(const std::string& output) {
  const std::filesystem::path name = std::filesystem::path(output).lexically_normal().filename();
  return name.empty() ? output : name.string();
}

/// `--view`: the live page served from its own thread for as long as the run lasts; the
/// pass's preview feeds it.
class ServedLiveView {
 public:
  ServedLiveView(const LiveCommandOptions& options, const CliContext& context)
      : view_(std::make_shared<LiveView>(folder_name(options.map.output))),
        server_(view_, options.three_folder) {
    const int port = server_.bind(options.view_host, options.view_port);
    // Always, also with --quiet: it is how the page is found.
    std::printf("map in the browser: http://%s:%d/\n", options.view_host.c_str(), port);
    if (!context.quiet && options.view_host != "127.0.0.1")
      std::printf("(listening on %s: the map is visible to the network)\n",
                  options.view_host.c_str());
    std::fflush(stdout);
    listener_ = std::thread([this] { server_.run(); });
  }
  ~ServedLiveView() {
    server_.stop();
    listener_.join();
  }
  ServedLiveView(const ServedLiveView&) = delete;
  ServedLiveView& operator=(const ServedLiveView&) = delete;

  mapping::MapPreviewSettings preview(const LiveCommandOptions& options) const {
    mapping::MapPreviewSettings settings;
    settings.interval_s = options.view_refresh_s;
    settings.max_chunks = options.view_max_chunks;
    const std::shared_ptr<LiveView> view = view_;
    settings.deliver = [view](mapping::MapPreview update) { view->take(std::move(update)); };
    return settings;
  }
  void finished() { view_->set_finished(); }

 private:
  std::shared_ptr<LiveView> view_;
  ViewServer server_;
  std::thread listener_;
};

void run_live(LiveCommandOptions& options, const CliContext& context) {
  const config::Config config = map_config(options.map, context);
  options.map.real_time = true;
  const StopSignal stop_signal(StopSignal::kMapMessage);
  std::unique_ptr<ServedLiveView> served;
  if (options.view) {
    served = std::make_unique<ServedLiveView>(options, context);
    options.map.preview = served->preview(options);
  }
  std::unique_ptr<slam::ScanSource> source =
      options.sensor.open(config, options.meta_path, options.map.output, stop_signal, context.quiet,
                          "Ctrl+C ends the run and writes the map");
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
  if (served) {
    served->finished();
    if (!context.quiet)
      std::printf("the finished map in the browser: featsense view %s\n",
                  options.map.output.c_str());
  }
}

}  // namespace

Command register_live(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<LiveCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "live",
      "Map a sensor on the network as it sends (Ouster or Velodyne UDP packets), until Ctrl+C "
      "or --idle-timeout: the TSDF map, the poses and a report, as `featsense map` writes them");
  options->sensor.add_to(*command, true);
  command->add_option("-o,--output", options->map.output, "Output folder")->required();
  command
      ->add_option("--meta", options->meta_path,
                   "Ouster: the sensor's metadata JSON (as the sensor's HTTP API serves it at "
                   "/api/v1/sensor/metadata, or a recording's)")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--reference-trajectory", options->map.reference_trajectory,
                   "A dry run's true path (TUM or KITTI), to compare the poses with in "
                   "report.json (a simulated recording's gt_trajectory.tum)")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--reference", options->map.reference,
                   "A dry run's true surface, to evaluate the mesh against (gt_mesh.ply)")
      ->check(CLI::ExistingFile);
  command->add_flag("--view", options->view,
                    "Show the map in the browser while it is made (prints the URL)");
  command
      ->add_option("--view-port", options->view_port, "--view: the page's port (0: any free one)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  command
      ->add_option("--view-host", options->view_host,
                   "--view: the address to serve on (another than 127.0.0.1 shows the map to "
                   "the network)")
      ->capture_default_str();
  command
      ->add_option("--view-refresh", options->view_refresh_s,
                   "--view: seconds between the map's refreshes (each re-meshes the chunks "
                   "that changed)")
      ->check(CLI::Range(0.1, 3600.0))
      ->capture_default_str();
  command
      ->add_option("--view-max-chunks", options->view_max_chunks,
                   "--view: chunks re-meshed per refresh at most, nearest the sensor first")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  command
      ->add_option("--three", options->three_folder,
                   "--view: folder of three.js (Debian's libjs-three)")
      ->capture_default_str();
  add_config_option(*command, kBackendOption, options->map.backend);
  add_map_output_flags(*command, options->map);
  return {command, [options, &context] { run_live(*options, context); }};
}

}  // namespace featsense::app
