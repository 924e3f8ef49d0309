// featsense localize MAP.h5 INPUT -o OUT: each scan's pose in a saved map, the map read only.

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "featsense/bench/measurements.hpp"
#include "featsense/mapping/localizer.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "json_output.hpp"
#include "live_input.hpp"
#include "localization_files.hpp"
#include "localize_plan.hpp"
#include "localize_report.hpp"
#include "map_options.hpp"
#include "progress.hpp"
#include "report_html.hpp"
#include "source_options.hpp"
#include "stop_signal.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

struct LocalizeOptions {
  std::string map;
  InputOptions input;
  LiveInputOptions live;  ///< --sensor: the scans from a sensor on the network
  bool plan = true;       ///< topdown.png: the map around the path (meshes that part of it)
  std::string output;
  std::optional<std::string> initial_pose;
  std::optional<std::string> gt;
  std::optional<uint64_t> start;
  std::optional<uint64_t> end;
};

/// A run that never found the sensor in the map: its own exit status, after the report.
constexpr int kNeverLocalizedExit = 3;

/// How much of the map around the path the plan view shows: enough for the streets and
/// rooms beside it, not the whole map of a city.
constexpr double kPlanMarginM = 15.0;

/// Seconds of input between two readings of the resident memory.
constexpr double kRssIntervalS = 30.0;

/// "12 localized, 3 on odometry, 40 lost" of scans counted by status.
std::string progress_text(const std::map<std::string, size_t>& by_status) {
  const auto count = [&](const char* status) {
    const auto it = by_status.find(status);
    return it == by_status.end() ? size_t{0} : it->second;
  };
  return std::to_string(count("localized")) + " localized, " + std::to_string(count("odometry")) +
         " on odometry, " + std::to_string(count("lost")) + " lost";
}

void log_summary(const LocalizeRun& run) {
  const mapping::LocalizerCounts& c = run.counts;
  if (!c.first_fix) return;
  const double seconds_in =
      1e-9 * static_cast<double>(c.first_fix->stamp_ns - run.scans.front().stamp_ns);
  spdlog::info("found after {:.1f} s of the recording ({} scans); {}", seconds_in,
               c.first_fix->scan, progress_text(c.by_status));
}

std::unique_ptr<slam::ScanSource> open_input(LocalizeOptions& options, const config::Config& config,
                                             const StopSignal& stop, bool quiet) {
  const bool live = !options.live.sensor.empty();
  // Both at once is refused by the command line (--sensor excludes INPUT).
  if (!live && options.input.input.empty())
    throw slam::InputError("nothing to localize: give a recording (INPUT) or a sensor (--sensor)");
  if (!live) return options.input.open(config);
  return options.live.open(config, options.input.meta_path, options.output, stop, quiet,
                           "Ctrl+C ends the run and writes the report");
}

void run_localize(LocalizeOptions& options, const CliContext& context) {
  const config::Config config = context.load_config();
  std::optional<Eigen::Isometry3d> initial_pose;
  if (options.initial_pose) initial_pose = parse_initial_pose(*options.initial_pose);
  std::optional<slam::Trajectory> truth;
  if (options.gt) truth = slam::read_trajectory(*options.gt, "auto", {});
  fs::create_directories(options.output);
  const fs::path folder(options.output);
  mapping::Localizer localizer(options.map, config, initial_pose);
  const StopSignal stop_signal("finishing the scan in hand and writing the poses");
  std::unique_ptr<slam::ScanSource> source =
      open_input(options, config, stop_signal, context.quiet);
  const mapping::LocalizerCounts opened = localizer.counts();
  spdlog::info("localizing {} ({}) in {} ({} keyframes, {} chunks){}", source->info().path,
               source->info().format, options.map, opened.map_keyframes, opened.map_chunks,
               initial_pose ? ", from the given initial pose" : "");

  // A live source has no length: the progress counts without a total.
  Progress progress("scans", source->info().frames, context.quiet);
  LocalizationFiles files(folder);
  LocalizeRun run;
  run.map = options.map;
  run.input = source->info();
  const auto start = std::chrono::steady_clock::now();
  std::map<std::string, size_t> by_status;
  const bool live = !options.live.sensor.empty();
  const std::string no_scan = run.input.path +
                              ": no scan came before the stop (is the sensor sending there? see "
                              "--host, --lidar-port)";
  while (!stop_signal.requested()) {
    std::optional<slam::Scan> scan;
    try {
      scan = source->next();
    } catch (const std::runtime_error&) {
      // A live source stopped before its first packet says it had none: say where from.
      if (live && stop_signal.requested() && run.scans.empty()) throw slam::InputError(no_scan);
      throw;
    }
    if (!scan) break;
    if (options.start && scan->sequence < *options.start) continue;
    if (options.end && scan->sequence > *options.end) break;
    run.scans.push_back(localizer.add_scan(*scan));
    const mapping::LocalizedScan& done = run.scans.back();
    files.add(done);
    // The memory every half minute of input: it must stay flat however long the run.
    const double input_s = 1e-9 * static_cast<double>(done.stamp_ns - run.scans.front().stamp_ns);
    if (run.rss_mb.empty() || input_s >= run.rss_mb.back().first + kRssIntervalS)
      run.rss_mb.emplace_back(input_s, bench::current_rss_mb());
    if (!done.event.empty()) {
      progress.finish();
      spdlog::info("scan {}: {}", done.sequence, done.event);
    }
    // Counted here: the localizer's counts() copies every timing of the run so far.
    ++by_status[mapping::to_string(done.status)];
    progress.update(run.scans.size(), progress_text(by_status));
  }
  progress.finish();
  run.interrupted = stop_signal.requested();
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.counts = localizer.counts();
  run.frames_skipped = source->stats().frames_skipped;
  run.warnings = source->stats().warning_count;
  run.input = source->info();

  nlohmann::json report = localize_report_json(config, run, truth);
  if (options.plan) {
    report["localization"]["plan"] = write_localize_plan(run, truth, folder, kPlanMarginM);
  }
  report["html"] = kReportHtml;
  write_json(report, (folder / "report.json").string());
  write_report_html(folder, report);
  log_summary(run);
  if (!context.quiet) {
    std::printf("%s: %zu scans, %s; trajectory.tum, localization.csv, report.json, %s in %s\n",
                run.counts.first_fix ? "localized" : "not localized", run.scans.size(),
                progress_text(run.counts.by_status).c_str(), kReportHtml, folder.string().c_str());
  }
  // Ctrl+C is how a live run ends; a recording stopped early says so.
  if (run.scans.empty()) {
    throw slam::InputError(live ? no_scan
                                : run.input.path +
                                      ": no scan to localize (--start and --end "
                                      "leave none)");
  }
  if (run.interrupted && !live) throw Interrupted("localization stopped; what was done is written");
  if (!run.counts.first_fix) {
    throw CommandFailed(
        run.input.path + " was never found in " + options.map + ": none of its " +
            std::to_string(run.scans.size()) + " scans matched the map (" +
            std::to_string(run.counts.unconfirmed_matches) +
            " keyframe matches that the map's surface did not confirm). The recording may show "
            "another place, or start where the map has not been (--initial-pose "
            "x,y,z,yaw_deg helps where that is known). No pose was given",
        kNeverLocalizedExit);
  }
}

}  // namespace

Command register_localize(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<LocalizeOptions>();
  CLI::App* command = app.add_subcommand(
      "localize",
      "Each scan's pose in a saved map, from a recording or a sensor on the network (found "
      "from anywhere by the map's keyframes, then tracked on its surface); the map is only "
      "read. Exit status 3: never found");
  command->add_option("MAP", options->map, "A map.h5 made by `featsense map`")
      ->required()
      ->check(CLI::ExistingFile);
  options->input.add_to(*command, true);
  options->live.add_to(*command, false);
  command->get_option("INPUT")->description(
      "The recording to localize (a file or folder, as `featsense map` reads), or none with "
      "--sensor");
  command->get_option("--sensor")->excludes(command->get_option("INPUT"));
  command->get_option("--meta")->description(
      "Ouster metadata JSON: a pcap's (default: found beside it), or with --sensor ouster the "
      "sensor's (or --sensor-address)");
  command
      ->add_option("-o,--output", options->output,
                   "Folder for trajectory.tum, localization.csv (both written as the scans come), "
                   "report.json, report.html and topdown.png")
      ->required();
  command->add_option("--initial-pose", options->initial_pose,
                      "x,y,z,yaw_deg: where the first scan is believed to be in the map; "
                      "narrows the first search to places within 10 m and 30 degrees of it");
  command
      ->add_option("--gt", options->gt,
                   "True poses in the map's frame (TUM or KITTI): each pose's error goes "
                   "into report.json")
      ->check(CLI::ExistingFile);
  command->add_option("--start", options->start, "First scan to localize (index)");
  command->add_option("--end", options->end, "Last scan to localize (index)");
  command->add_flag("!--no-plan", options->plan,
                    "No topdown.png (it meshes the map around the path when the run ends)");
  return {command, [options, &context] { run_localize(*options, context); }};
}

}  // namespace featsense::app
