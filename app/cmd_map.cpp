// featsense map INPUT -o OUT [--gt TRAJ]: a recording (and its poses, else the odometry's)
// in; the map (map.h5), the poses used (trajectory.tum / .kitti) and report.json out.

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "eval_json.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/slam/odometry/odometry_locator.hpp"
#include "featsense/slam/refine/segment_refiner.hpp"
#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"
#include "featsense/tsdf/integrator.hpp"
#include "front_end_report.hpp"
#include "json_output.hpp"
#include "map_job.hpp"
#include "map_outputs.hpp"
#include "map_pipeline.hpp"
#include "map_report.hpp"
#include "map_store.hpp"
#include "source_options.hpp"
#include "stop_signal.hpp"
#include "timing_stats.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

/// --start / --end: a frame index ("120") or seconds after the first scan ("12.5s").
void parse_range_end(const std::string& text, const char* option, std::optional<uint64_t>& frame,
                     std::optional<double>& seconds) {
  std::istringstream in(text);
  double value = 0.0;
  if (!(in >> value) || value < 0.0) {
    throw config::ConfigError(std::string(option) + ": expected a frame index or seconds like " +
                              "12.5s, got '" + text + "'");
  }
  std::string unit;
  in >> unit;
  if (unit == "s") {
    seconds = value;
  } else if (unit.empty() && value == static_cast<double>(static_cast<uint64_t>(value))) {
    frame = static_cast<uint64_t>(value);
  } else {
    throw config::ConfigError(std::string(option) + ": expected a frame index or seconds like " +
                              "12.5s, got '" + text + "'");
  }
}

FrameRange frame_range(const MapOptions& options) {
  FrameRange range;
  if (options.start) parse_range_end(*options.start, "--start", range.first_frame, range.first_s);
  if (options.end) parse_range_end(*options.end, "--end", range.last_frame, range.last_s);
  return range;
}

slam::Trajectory read_poses(const MapOptions& options) {
  if (options.gt_times && options.gt_format == "tum") {
    throw config::ConfigError("--gt-times goes with KITTI poses, not --gt-format tum");
  }
  return slam::read_trajectory(*options.gt, options.gt_format, options.gt_times);
}

/// The ground truth of a simulated recording (gt_trajectory.tum in its folder), if any.
std::optional<KnownTrajectory> ground_truth_beside(const slam::SourceInfo& info) {
  const fs::path file = fs::path(info.path) / "gt_trajectory.tum";
  if (!fs::is_directory(info.path) || !fs::is_regular_file(file)) return std::nullopt;
  try {
    return KnownTrajectory{slam::read_tum(file.string()), true};
  } catch (const slam::TrajectoryError& e) {
    spdlog::warn("ignoring the ground truth beside the recording: {}", e.what());
    return std::nullopt;
  }
}

/// --reference-trajectory, else the ground truth beside a simulated recording (only where the
/// poses are estimated: given poses are that truth).
std::optional<KnownTrajectory> known_trajectory(const MapOptions& options,
                                                const slam::SourceInfo& info) {
  if (options.reference_trajectory) {
    return KnownTrajectory{slam::read_trajectory(*options.reference_trajectory, "auto", {}), false};
  }
  if (options.gt) return std::nullopt;
  return ground_truth_beside(info);
}

std::string format_metres(double metres) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g m", metres);
  return text;
}

tsdf::Vec3 position_of(const Eigen::Isometry3d& pose) {
  const Eigen::Vector3d t = pose.translation();
  return {static_cast<float>(t.x()), static_cast<float>(t.y()), static_cast<float>(t.z())};
}

}  // namespace

config::Config map_config(const MapOptions& options, const CliContext& context) {
  std::vector<config::Override> overrides;
  add_config_override(overrides, kBackendOption, options.backend);
  return context.load_config(overrides);
}

MapOutcome run_map(const MapOptions& options, const CliContext& context) {
  config::Config config = map_config(options, context);
  frame_range(options);  // bad --start / --end fail before the recording is opened
  std::optional<slam::Trajectory> poses;
  if (options.gt) poses = read_poses(options);
  std::unique_ptr<slam::ScanSource> source = options.input.open(config);
  const std::optional<KnownTrajectory> truth = known_trajectory(options, source->info());
  return map_recording(*source, std::move(poses), truth, options, config,
                       find_mesh_references(options.input.input, options.reference), context);
}

MapOutcome map_recording(slam::ScanSource& source, std::optional<slam::Trajectory> poses,
                         const std::optional<KnownTrajectory>& truth, const MapOptions& options,
                         config::Config config, const MeshReferences& references,
                         const CliContext& context) {
  const FrameRange range = frame_range(options);
  const slam::SourceInfo& info = source.info();
  std::unique_ptr<slam::odometry::OdometryLocator> odometry;
  std::unique_ptr<slam::ScanLocator> given;
  if (poses) {
    given = slam::make_given_pose_locator(std::move(*poses), config.odometry.deskew);
  } else {
    const bool anchored = truth && truth->starts_at_first_scan && !truth->poses.empty();
    odometry = slam::odometry::make_odometry_locator(
        config, anchored ? truth->poses.poses.front() : Eigen::Isometry3d::Identity());
  }
  slam::ScanLocator* locator = given ? given.get() : odometry.get();

  const fs::path out(options.output);
  fs::create_directories(out);
  MapStore map_store = open_map_store(out / "map.h5", config, info.sensor.name,
                                      options.continue_from, options.overwrite);
  storage::Hdf5ChunkStore& store = *map_store.store;
  const tsdf::TsdfSettings settings = tsdf::TsdfSettings::from_config(config.map, info.sensor);

  std::unique_ptr<tsdf::Integrator> integrator;
  std::unique_ptr<storage::ShiftingMap> map;
  std::string backend_reason;
  const MapOpener open_map = [&](const LocatedScan& first) -> storage::ShiftingMap& {
    integrator = tsdf::make_integrator(config.map.backend, settings,
                                       position_of(first.placement.T_map_sensor), &backend_reason);
    spdlog::info("TSDF: {}", backend_reason);
    map = std::make_unique<storage::ShiftingMap>(*integrator, store, config.map.shift_threshold_m);
    return *map;
  };

  PipelineSettings pipeline;
  pipeline.flush_interval_s = config.map.flush_interval_s;
  pipeline.range = range;
  pipeline.total_frames = info.frames;
  pipeline.quiet = context.quiet;
  pipeline.drop_mixed_pixels = config.sensor.drop_mixed_pixels;
  if (odometry && config.refine.enabled) pipeline.refine = slam::refine::from_config(config);
  spdlog::info("mapping {} ({}; per-point times {}) with {}{}", info.path, info.format,
               info.times.empty() ? std::string("unknown") : info.times, locator->description(),
               pipeline.refine ? ", refined every " + format_metres(pipeline.refine->distance_m)
                               : std::string());

  PipelineResult result;
  MapRunSummary summary;
  {
    const StopSignal stop_signal;
    try {
      result = run_map_pipeline(source, *locator, open_map, pipeline);
    } catch (...) {
      // Whatever was integrated goes to disk before the error is reported.
      try {
        if (map) map->sync();
        store.close();
      } catch (const std::exception& e) {
        spdlog::error("could not write the map after the failure: {}", e.what());
      }
      throw;
    }
    if (map) {
      const auto start = std::chrono::steady_clock::now();
      map->sync();
      summary.final_flush_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
    }
    slam::Trajectory all_poses = map_store.earlier_poses;
    for (size_t i = 0; i < result.poses.size(); ++i) {
      all_poses.push_back(result.poses.stamps_ns[i], result.poses.poses[i]);
    }
    store.write_trajectory(to_store_poses(all_poses));
    summary.map_chunks = store.keys().size();
    store.close();
  }
  slam::write_tum(result.poses, (out / "trajectory.tum").string());
  slam::write_kitti(result.poses, (out / "trajectory.kitti").string());

  summary.config = &config;
  summary.input = &info;
  summary.backend = integrator ? integrator->backend_name() : "none";
  summary.backend_reason = backend_reason;
  summary.poses = locator->description() + (pipeline.refine ? ", refined (VGICP)" : "");
  summary.pipeline = &result;
  if (map) summary.map = map->stats();
  summary.continued_chunks = map_store.continued_chunks;
  if (integrator && integrator->backend_name() == "cuda") {
    summary.device_memory_bytes = integrator->memory_bytes();
  }
  nlohmann::json report = map_report_json(summary);
  if (odometry) {
    const slam::odometry::OdometryCounts counts = odometry->counts();
    report["odometry"] = odometry_json(counts, config.odometry.intensity_fusion);
    if (config.odometry.intensity_fusion && counts.intensity_confirmed_scans < counts.scans) {
      spdlog::warn("intensity fusion {}: edges were taken from the geometry alone",
                   intensity_fusion_text(counts, true));
    }
  }
  if (pipeline.refine) report["refine"] = refine_json(result, *pipeline.refine);
  if (truth && result.poses.size() >= 2) {
    try {
      const slam::TrajectoryEvaluationSettings eval_settings;
      report["eval"]["traj"] = trajectory_evaluation_json(
          slam::evaluate_trajectory(result.poses, truth->poses, eval_settings), eval_settings);
      // The odometry's own poses too, to show what the refinement changed.
      if (result.unrefined_poses && result.unrefined_poses->size() >= 2) {
        report["eval"]["traj_unrefined"] = trajectory_evaluation_json(
            slam::evaluate_trajectory(*result.unrefined_poses, truth->poses, eval_settings),
            eval_settings);
      }
    } catch (const slam::TrajectoryError& e) {
      spdlog::warn("the trajectory could not be compared with the ground truth: {}", e.what());
    }
  }
  if (!options.no_mesh && result.frames_mapped > 0) {
    const MapMesh meshed = mesh_map(out / "map.h5", out);
    report["mesh"] = mesh_json(meshed);
    if (std::optional<nlohmann::json> evaluation = evaluate_map_mesh(meshed.mesh, references)) {
      report["eval"]["mesh"] = *evaluation;
    }
  }
  write_json(report, (out / "report.json").string());

  if (result.frames_mapped == 0) {
    throw std::runtime_error("no scan was mapped" + (result.warnings.empty()
                                                         ? std::string()
                                                         : ": " + result.warnings.front()));
  }
  if (result.interrupted) {
    throw Interrupted("interrupted after " + std::to_string(result.frames_mapped) +
                      " scans; their map, poses and report are in " + out.string());
  }
  if (!context.quiet && options.print_summary) {
    std::printf("%s%zu scans mapped in %.1f s (%.1f scans/s, %s), %zu chunks, %zu shifts -> %s\n",
                result.interrupted ? "interrupted: " : "", result.frames_mapped, result.wall_s,
                result.wall_s > 0 ? static_cast<double>(result.frames_mapped) / result.wall_s : 0.0,
                summary.backend.c_str(), summary.map_chunks, summary.map.shifts,
                out.string().c_str());
  }
  return {out, report};
}

Command register_map(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<MapOptions>();
  CLI::App* command = app.add_subcommand(
      "map",
      "Map a recording: the TSDF map (map.h5), the poses (given by --gt, else estimated by the "
      "odometry) and a report");
  options->input.add_to(*command, false);
  command->add_option("-o,--output", options->output, "Output folder")->required();
  command->add_option("--gt", options->gt,
                      "The sensor's poses: TUM (interpolated to each scan's and column's time) or "
                      "KITTI (one pose per scan); without it the odometry estimates them");
  command->add_option("--gt-format", options->gt_format, "Format of --gt: auto, tum or kitti")
      ->check(CLI::IsMember({"auto", "tum", "kitti"}));
  command->add_option("--gt-times", options->gt_times, "Times file of KITTI poses (times.txt)")
      ->check(CLI::ExistingFile);
  add_config_option(*command, kBackendOption, options->backend);
  command->add_option("--continue", options->continue_from,
                      "Continue an existing map (.h5 or .vdb): its voxel size and tau are kept "
                      "(map.voxel_size and map.truncation, if set, must be the same)");
  command->add_option("--start", options->start,
                      "First scan to map: a frame index, or seconds after the first scan (12.5s)");
  command->add_option("--end", options->end, "Last scan to map (as --start)");
  command->add_flag("--overwrite", options->overwrite, "Replace OUT/map.h5 if it exists");
  command->add_flag("--no-mesh", options->no_mesh, "Write the map only, no mesh.ply / mesh.glb");
  command
      ->add_option("--reference-trajectory", options->reference_trajectory,
                   "The true path (TUM or KITTI), to compare the poses with in report.json "
                   "(default: the ground truth of a simulated sequence)")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--reference", options->reference,
                   "Surveyed mesh to evaluate the map's mesh against (default: the ground "
                   "truth of a simulated sequence)")
      ->check(CLI::ExistingFile);
  return {command, [options, &context] { run_map(*options, context); }};
}

}  // namespace featsense::app
