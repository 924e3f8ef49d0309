// featsense map INPUT -o OUT [--gt TRAJ]: a recording (and its poses, else the odometry's)
// in; the map (map.h5), the poses used (trajectory.tum / .kitti) and report.json out.

#include <spdlog/spdlog.h>
#include <Eigen/Eigenvalues>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "eval_json.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/mapping/mapper.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"
#include "front_end_report.hpp"
#include "json_output.hpp"
#include "map_job.hpp"
#include "map_options.hpp"
#include "map_outputs.hpp"
#include "map_report.hpp"
#include "progress.hpp"
#include "report_html.hpp"
#include "session_links_report.hpp"
#include "source_options.hpp"
#include "stop_signal.hpp"
#include "trajectory_error_plot.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

slam::Trajectory read_poses(const MapOptions& options) {
  if (options.gt_times && options.gt_format == "tum") {
    throw config::ConfigError("--gt-times goes with KITTI poses, not --gt-format tum");
  }
  return slam::read_trajectory(*options.gt, options.gt_format, options.gt_times);
}

/// The ground truth of a simulated recording (gt_trajectory.tum in its folder, or beside a
/// simulated pcap), if any.
std::optional<KnownTrajectory> ground_truth_beside(const slam::SourceInfo& info) {
  const std::optional<fs::path> folder = simulation_truth_folder(info.path);
  if (!folder) return std::nullopt;
  const fs::path file = *folder / "gt_trajectory.tum";
  if (!fs::is_regular_file(file)) return std::nullopt;
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

/// The positions of a path spread at least this much (standard deviation) along a second
/// direction: the alignment of two paths then fixes the rotation about the first one too.
constexpr double kMinAlignmentSpreadM = 2.0;

/// Whether the path's positions spread `min_m` (standard deviation) in two directions: a
/// straight path leaves the rotation about itself to chance in any alignment.
bool spans_a_plane(const slam::Trajectory& path, double min_m) {
  if (path.size() < 3) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Isometry3d& T : path.poses) mean += T.translation();
  mean /= static_cast<double>(path.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Isometry3d& T : path.poses) {
    const Eigen::Vector3d d = T.translation() - mean;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(path.size());
  const Eigen::Vector3d spread =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues();  // ascending
  return spread(1) >= min_m * min_m;
}

/// What topdown.png draws: the poses the map was made with and, where it lies in the map's
/// frame (a simulation's, which the map starts from), the true path. A --reference-trajectory
/// is in a frame of its own (the evaluation aligns it): it is not drawn.
PlanInputs plan_inputs(const MapOptions& options, const slam::Trajectory& final_poses,
                       bool given_poses, const std::optional<KnownTrajectory>& truth) {
  PlanInputs plan;
  plan.settings.cut_height_m = options.plan_height;
  if (truth && truth->starts_at_first_scan) {
    plan.paths.push_back(
        plan_path(truth->poses, viewer_export::PlanPath::Kind::kTruth, "true path"));
  }
  plan.paths.push_back(plan_path(final_poses, viewer_export::PlanPath::Kind::kEstimate,
                                 given_poses ? "given path" : "estimated path"));
  return plan;
}

/// A pass's speed, for the report of a run that mapped twice.
nlohmann::json pass_json(const mapping::PassResult& run) {
  return {
      {"scans", run.frames_mapped},
      {"wall_s", run.wall_s},
      {"scans_per_s", run.wall_s > 0 ? static_cast<double>(run.frames_mapped) / run.wall_s : 0.0}};
}

}  // namespace

config::Config map_config(const MapOptions& options, const CliContext& context) {
  std::vector<config::Override> overrides;
  add_config_override(overrides, kBackendOption, options.backend);
  if (options.no_loop_closure) overrides.push_back({"loop.enabled", "false", "--no-loop-closure"});
  return context.load_config(overrides);
}

MapOutcome run_map(const MapOptions& options, const CliContext& context) {
  config::Config config = map_config(options, context);
  frame_range(options);  // bad --start / --end fail before the recording is opened
  std::optional<slam::Trajectory> poses;
  if (options.gt) poses = read_poses(options);
  std::unique_ptr<slam::ScanSource> source = options.input.open(config);
  const std::optional<KnownTrajectory> truth = known_trajectory(options, source->info());
  // A file can be read again: the second pass of the loop closure.
  const SourceReopener reopen = [&options, config] { return options.input.open(config); };
  return map_recording(*source, std::move(poses), truth, options, config,
                       find_mesh_references(options.input.input, options.reference), context,
                       reopen);
}

namespace {

/// The Mapper's settings for this run: where the map goes, the poses (given, else the
/// odometry's, anchored at the true first pose where the truth is known), the session.
mapping::MapperSettings mapper_settings(const slam::SourceInfo& info,
                                        std::optional<slam::Trajectory> poses,
                                        const std::optional<KnownTrajectory>& truth,
                                        const MapOptions& options, config::Config config,
                                        const SourceReopener& reopen) {
  mapping::MapperSettings settings;
  settings.real_time = options.real_time;
  settings.preview = options.preview;
  settings.config = std::move(config);
  settings.sensor = info.sensor;
  settings.map_path = fs::path(options.output) / "map.h5";
  settings.overwrite = options.overwrite;
  settings.continue_from = options.continue_from;
  settings.integrate = !options.poses_only;
  settings.reopen = reopen;
  settings.range = frame_range(options);
  // The input's absolute path: a later session may map it again from elsewhere. An address
  // (a live sensor's udp://...) stays as it is.
  std::error_code no_path;
  const bool address = info.path.find("://") != std::string::npos;
  const fs::path absolute_input = address ? fs::path(info.path) : fs::absolute(info.path, no_path);
  settings.session = {no_path || address ? info.path : absolute_input.lexically_normal().string(),
                      info.format, "given poses"};
  if (poses) {
    settings.given_poses = std::move(poses);
    return settings;
  }
  // The odometry's map frame is the first scan's, or the true first pose's where the truth is
  // known (a recording continuing a map starts in its own frame until it is placed).
  const bool anchored =
      truth && truth->starts_at_first_scan && !truth->poses.empty() && !options.continue_from;
  if (anchored) settings.T_map_first_scan = truth->poses.poses.front();
  settings.session.placement =
      anchored ? "odometry from the true first pose" : "odometry, the map frame at the first scan";
  if (options.continue_from && options.initial_pose)
    settings.initial_guess = parse_initial_pose(*options.initial_pose);
  return settings;
}

void log_start(const slam::SourceInfo& info, const mapping::Mapper& mapper) {
  const std::optional<slam::refine::RefineSettings>& refine = mapper.refine_settings();
  spdlog::info("mapping {} ({}; per-point times {}) with {}{}{}", info.path, info.format,
               info.times.empty() ? std::string("unknown") : info.times, mapper.front_end(),
               refine ? ", refined every " + format_metres(refine->distance_m) : std::string(),
               mapper.loops_off_because().empty() ? ", loops closed" : std::string());
  if (mapper.estimates_poses() && !mapper.loops_off_because().empty())
    spdlog::info("loop closure off: {}", mapper.loops_off_because());
  if (!info.imu.empty()) spdlog::info("IMU: {}", info.imu);
}

/// Runs the Mapper over `source` with Ctrl+C mapped onto its stop token. A recording that
/// could not be placed in a saved map leaves a report.json that says why.
mapping::MapResult run_mapper(slam::ScanSource& source, mapping::MapperSettings settings,
                              const fs::path& out, const CliContext& context,
                              const StopSignal* caller_signal) {
  std::optional<StopSignal> own_signal;
  if (caller_signal == nullptr) own_signal.emplace();
  const StopSignal& stop_signal = caller_signal != nullptr ? *caller_signal : *own_signal;
  const mapping::RunEvents events = terminal_events(stop_signal.token(), context.quiet);
  try {
    mapping::Mapper mapper(std::move(settings), events);
    log_start(source.info(), mapper);
    return mapping::map_source(source, mapper);
  } catch (const mapping::RelocalizationFailed& e) {
    write_json({{"input", source.info().path},
                {"format", source.info().format},
                {"status", "refused: not placed in the saved map"},
                {"relocalization", relocalization_json(e.report())}},
               (out / "report.json").string());
    throw;
  }
}

/// What the front end did: the odometry, the refinement, the loops, the sessions of the map
/// and, continuing a map, where the recording was placed.
void add_front_end_report(const mapping::MapResult& result, const config::Config& config,
                          const fs::path& out, bool integrate, nlohmann::json& report) {
  if (result.odometry) {
    const slam::odometry::OdometryCounts& counts = *result.odometry;
    report["odometry"] = odometry_json(counts, config.odometry.intensity_fusion);
    if (config.odometry.intensity_fusion && counts.intensity_confirmed_scans < counts.scans) {
      spdlog::warn("intensity fusion {}: edges were taken from the geometry alone",
                   intensity_fusion_text(counts, true));
    }
  }
  if (result.refine) report["refine"] = refine_json(result.first, *result.refine);
  // Every run that made the map, this one last.
  if (integrate && fs::exists(out / "map.h5")) report["sessions"] = sessions_json(out / "map.h5");
  if (result.relocalization) report["relocalization"] = relocalization_json(*result.relocalization);
  if (result.first.loops) {
    report["loops"] = loops_json(*result.first.loops, result.first.timings.loops_finish_ms);
    report["loops"]["second_pass"] = result.second_pass.reason;
    report["loops"]["first_pass"] = pass_json(result.first);
    if (result.second) report["loops"]["second_pass_run"] = pass_json(*result.second);
  } else if (result.odometry) {
    report["loops"] = {{"enabled", false}, {"why", result.loops_off_because}};
  }
}

/// eval.traj (and the path's error plot) where the truth is known. Returns the alignment of
/// the estimated path to the true one where it fixes a rotation (estimated poses only), to
/// score the mesh in that frame too.
std::optional<Eigen::Isometry3d> add_trajectory_evaluation(
    const mapping::MapResult& result, const std::optional<KnownTrajectory>& truth,
    const fs::path& out, nlohmann::json& report) {
  const slam::Trajectory& final_poses = result.final_poses;
  if (!truth || final_poses.size() < 2) return std::nullopt;
  std::optional<Eigen::Isometry3d> T_truth_estimate;
  try {
    const slam::TrajectoryEvaluationSettings eval_settings;
    const auto evaluate = [&](const slam::Trajectory& trajectory) {
      return trajectory_evaluation_json(
          slam::evaluate_trajectory(trajectory, truth->poses, eval_settings), eval_settings);
    };
    const slam::TrajectoryEvaluation final_evaluation =
        slam::evaluate_trajectory(final_poses, truth->poses, eval_settings);
    report["eval"]["traj"] = trajectory_evaluation_json(final_evaluation, eval_settings);
    const bool spans_plane = spans_a_plane(final_poses, kMinAlignmentSpreadM);
    TrajectoryErrorSeries series =
        trajectory_error_series(final_evaluation, truth->poses, final_poses.stamps_ns.front());
    series.rotation_fixed = spans_plane;
    report["eval"]["traj"]["error_files"] = write_trajectory_error_png(
        out, series, report.contains("loops") ? report["loops"] : nlohmann::json::object());
    // The mesh lies in the frame of the poses it was made with: after a second pass the final
    // ones, else (a live run, an interrupted one) the first pass's, before the loops' and
    // gravity's corrections.
    if (result.odometry && spans_plane) {
      const slam::Trajectory& mapped_poses = result.mapped().poses;
      T_truth_estimate =
          mapped_poses.size() < 2
              ? final_evaluation.alignment.T
              : slam::evaluate_trajectory(mapped_poses, truth->poses, eval_settings).alignment.T;
    }
    // The front end's own poses too, to show what the loops and the refinement changed.
    const std::optional<mapping::LoopOutcome>& loops = result.first.loops;
    if (loops && loops->corrects_poses())
      report["eval"]["traj_before_loops"] = evaluate(result.first.poses);
    if (result.first.unrefined_poses && result.first.unrefined_poses->size() >= 2)
      report["eval"]["traj_unrefined"] = evaluate(*result.first.unrefined_poses);
  } catch (const slam::TrajectoryError& e) {
    spdlog::warn("the trajectory could not be compared with the ground truth: {}", e.what());
  }
  return T_truth_estimate;
}

}  // namespace

MapOutcome map_recording(slam::ScanSource& source, std::optional<slam::Trajectory> poses,
                         const std::optional<KnownTrajectory>& truth, const MapOptions& options,
                         config::Config config, const MeshReferences& references,
                         const CliContext& context, const SourceReopener& reopen,
                         const StopSignal* stop_signal) {
  const slam::SourceInfo& info = source.info();
  const fs::path out(options.output);
  fs::create_directories(out);
  const mapping::MapResult result = run_mapper(
      source, mapper_settings(info, std::move(poses), truth, options, std::move(config), reopen),
      out, context, stop_signal);
  // With a continued map's voxel size and tau: the configuration the map keeps.
  const config::Config& used = result.config;
  const mapping::PassResult& mapped = result.mapped();
  slam::write_tum(result.final_poses, (out / "trajectory.tum").string());
  slam::write_kitti(result.final_poses, (out / "trajectory.kitti").string());

  nlohmann::json report = map_report_json(used, info, result);
  add_front_end_report(result, used, out, !options.poses_only, report);
  const std::optional<Eigen::Isometry3d> T_truth_estimate =
      add_trajectory_evaluation(result, truth, out, report);
  if (!options.no_mesh && !options.poses_only && mapped.frames_mapped > 0) {
    const MeshErrorOutputs error_outputs{
        out, plan_inputs(options, result.final_poses, !result.odometry, truth)};
    if (options.tiles) {
      // The full-resolution tiles are compared with the truth, not the overview (a coarser
      // level: that would measure the simplification, not the map).
      report["mesh"] =
          mesh_json(mesh_map_tiles(out / "map.h5", out, error_outputs.plan, context.quiet));
      if (std::optional<nlohmann::json> evaluation =
              evaluate_tile_set(out / "tiles", references, T_truth_estimate)) {
        report["eval"]["mesh"] = *evaluation;
      }
    } else {
      const MapMesh meshed = mesh_map(out / "map.h5", out, error_outputs.plan);
      report["mesh"] = mesh_json(meshed);
      if (std::optional<nlohmann::json> evaluation =
              evaluate_map_mesh(meshed.mesh, references, T_truth_estimate, &error_outputs)) {
        report["eval"]["mesh"] = *evaluation;
      }
    }
  }
  report["html"] = kReportHtml;
  write_json(report, (out / "report.json").string());
  write_report_html(out, report);

  if (mapped.frames_mapped == 0) {
    throw std::runtime_error("no scan was mapped" + (mapped.warnings.empty()
                                                         ? std::string()
                                                         : ": " + mapped.warnings.front()));
  }
  if (mapped.interrupted) {
    throw Interrupted("interrupted after " + std::to_string(mapped.frames_mapped) +
                      " scans; their map, poses and report are in " + out.string());
  }
  if (!context.quiet && options.print_summary) {
    std::printf("%zu scans mapped in %.1f s (%.1f scans/s, %s), %zu chunks, %zu shifts -> %s\n",
                mapped.frames_mapped, mapped.wall_s, mapped.scans_per_s(), mapped.backend.c_str(),
                mapped.map_chunks, mapped.map.shifts, out.string().c_str());
    const mapping::RealTimeCounts& kept_up = mapped.real_time;
    if (kept_up.scans_dropped() + kept_up.integrations_skipped + kept_up.keyframes_skipped +
            kept_up.refinement_clouds_skipped >
        0) {
      std::printf(
          "to keep up: %zu integrations skipped (poses kept), %zu refinement clouds skipped, "
          "%zu scans dropped, %zu keyframes skipped\n",
          kept_up.integrations_skipped, kept_up.refinement_clouds_skipped, kept_up.scans_dropped(),
          kept_up.keyframes_skipped);
    }
  }
  return {out, report};
}

void add_map_output_flags(CLI::App& command, MapOptions& options) {
  command.add_flag("--overwrite", options.overwrite, "Replace OUT/map.h5 if it exists");
  command.add_flag("--no-mesh", options.no_mesh,
                   "Write the map only, no mesh.ply / mesh.glb / topdown.png");
  command.add_flag("--tiles", options.tiles,
                   "The mesh as a tile set (OUT/tiles/: a mesh per tile, 3D Tiles), memory "
                   "bounded by a tile, for large maps");
  command.add_flag("--no-loop-closure", options.no_loop_closure,
                   "Map with the odometry's poses alone (loop.enabled false)");
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
  command->add_option("--initial-pose", options->initial_pose,
                      "With --continue and no --gt: where the recording's first scan lies in the "
                      "map, roughly, as x,y,z,yaw_deg (it is still verified)");
  command->add_option("--start", options->start,
                      "First scan to map: a frame index, or seconds after the first scan (12.5s)");
  command->add_option("--end", options->end, "Last scan to map (as --start)");
  add_map_output_flags(*command, *options);
  add_plan_height_option(*command, options->plan_height);
  command->add_flag("--poses-only", options->poses_only,
                    "Estimate the poses (odometry, refinement, loops) and write trajectory.tum "
                    "and the report only, no map: map later with --gt trajectory.tum");
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
