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
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/odometry/odometry_locator.hpp"
#include "featsense/slam/refine/segment_refiner.hpp"
#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/slam/trajectory/scan_motions.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"
#include "front_end_report.hpp"
#include "json_output.hpp"
#include "map_continue.hpp"
#include "map_job.hpp"
#include "map_outputs.hpp"
#include "map_pass.hpp"
#include "map_pipeline.hpp"
#include "map_report.hpp"
#include "map_sessions.hpp"
#include "map_store.hpp"
#include "report_html.hpp"
#include "source_options.hpp"
#include "stop_signal.hpp"
#include "timing_stats.hpp"
#include "trajectory_error_plot.hpp"

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

/// Why the loop closure does not run (empty: it does).
std::string loop_closure_off_because(bool odometry, const config::Config& config) {
  if (!odometry) return "the poses are given";
  if (!config.loop.enabled) return "loop.enabled is false";
  return "";
}

/// A pass's speed, for the report of a run that mapped twice.
nlohmann::json pass_json(const PipelineResult& run) {
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

MapOutcome map_recording(slam::ScanSource& source, std::optional<slam::Trajectory> poses,
                         const std::optional<KnownTrajectory>& truth, const MapOptions& options,
                         config::Config config, const MeshReferences& references,
                         const CliContext& context, const SourceReopener& reopen) {
  const FrameRange range = frame_range(options);
  const slam::SourceInfo& info = source.info();
  std::unique_ptr<slam::odometry::OdometryLocator> odometry;
  std::unique_ptr<slam::ScanLocator> given;
  if (poses) {
    given = slam::make_given_pose_locator(std::move(*poses), config.odometry.deskew);
  } else {
    // A recording continuing a map starts in its own frame until it is placed in the map.
    const bool anchored =
        truth && truth->starts_at_first_scan && !truth->poses.empty() && !options.continue_from;
    odometry = slam::odometry::make_odometry_locator(
        config, anchored ? truth->poses.poses.front() : Eigen::Isometry3d::Identity());
  }
  slam::ScanLocator* locator = given ? given.get() : odometry.get();

  const fs::path out(options.output);
  fs::create_directories(out);
  PipelineSettings pipeline;
  pipeline.flush_interval_s = config.map.flush_interval_s;
  pipeline.range = range;
  pipeline.total_frames = info.frames;
  pipeline.quiet = context.quiet;
  pipeline.drop_mixed_pixels = config.sensor.drop_mixed_pixels;
  pipeline.integrate = !options.poses_only;
  if (odometry && config.refine.enabled) pipeline.refine = slam::refine::from_config(config);
  const std::string no_loops = loop_closure_off_because(odometry != nullptr, config);
  if (no_loops.empty()) pipeline.loops = slam::loops::from_config(config);
  spdlog::info("mapping {} ({}; per-point times {}) with {}{}{}", info.path, info.format,
               info.times.empty() ? std::string("unknown") : info.times, locator->description(),
               pipeline.refine ? ", refined every " + format_metres(pipeline.refine->distance_m)
                               : std::string(),
               pipeline.loops ? ", loops closed" : std::string());
  if (odometry && !no_loops.empty()) spdlog::info("loop closure off: {}", no_loops);
  if (!info.imu.empty()) spdlog::info("IMU: {}", info.imu);

  // The run as the map's session: with given poses they place it; the odometry's map frame
  // is the first scan's, or the true first pose's where the truth is known.
  // The input's absolute path: a later session may map it again from elsewhere.
  std::error_code no_path;
  const fs::path absolute_input = fs::absolute(info.path, no_path);
  SessionDescription session{no_path ? info.path : absolute_input.lexically_normal().string(),
                             info.format, "given poses"};
  if (odometry) {
    session.placement =
        truth && truth->starts_at_first_scan && !truth->poses.empty() && !options.continue_from
            ? "odometry from the true first pose"
            : "odometry, the map frame at the first scan";
  }
  MapPassOutput pass;
  PipelineResult first;  // the odometry's poses, before the loops
  std::string second_pass = "no loop closed, no gravity";
  std::optional<PipelineResult> second;
  std::optional<ContinuedRun> continued;
  if (odometry && options.continue_from) {
    // A bare recording into a saved map: placed by its keyframes first (map_continue.hpp).
    ContinueRequest request{*options.continue_from, out,     info.sensor.name,
                            options.overwrite,      session, std::nullopt};
    if (options.initial_pose) request.guess = parse_initial_pose(*options.initial_pose);
    try {
      continued = map_into_saved_map(source, *odometry, pipeline, config, request, reopen);
    } catch (const RelocalizationFailed& e) {
      write_json({{"input", info.path},
                  {"format", info.format},
                  {"status", "refused: not placed in the saved map"},
                  {"relocalization", e.report()}},
                 (out / "report.json").string());
      throw;
    }
    pass = std::move(continued->pass);
    first = std::move(continued->first);
    second = pass.result;
    second_pass = continued->second_pass;
  } else {
    pass = run_map_pass(
        source, *locator, pipeline, config,
        {out / "map.h5", info.sensor.name, options.continue_from, options.overwrite, session});
    first = pass.result;
  }
  const std::optional<LoopOutcome>& loops = first.loops;
  // Levelled by gravity alone, the poses may move less than the map can show: then the first
  // map stays (a second pass would double the run for nothing).
  const double quarter_voxel_m = 0.25 * config.map.voxel_size_m;
  const bool levelled_only = loops && loops->loops.empty() && loops->gravity.observations > 0;
  if (continued) {
    // Mapped once, with the poses placed and corrected in the saved map.
  } else if (levelled_only && loops->corrections_max_m < quarter_voxel_m) {
    char why[160];
    std::snprintf(why, sizeof why,
                  "levelled by gravity, no scan moved more than a quarter voxel (%.1f mm): the "
                  "map stays",
                  1000.0 * loops->corrections_max_m);
    second_pass = why;
  } else if (loops && loops->corrects_poses()) {
    if (first.interrupted) {
      second_pass = "interrupted: the map keeps the odometry's poses";
    } else if (options.poses_only) {
      second_pass = "--poses-only: no map";
    } else if (!reopen) {
      second_pass = "the input cannot be read twice: the map keeps the odometry's poses";
    } else {
      // The recording again, with the corrected poses, into a new file that replaces the
      // first map only once it is complete.
      spdlog::info("{} loops closed{}: mapping the recording again with the corrected poses",
                   loops->loops.size(),
                   loops->gravity.observations > 0 ? ", levelled by gravity" : "");
      const fs::path replay_path = out / "map.corrected.h5";
      std::optional<MapPassOutput> replayed;
      bool replay_interrupted = false;
      try {
        build_then_replace(replay_path, out / "map.h5", [&] {
          const std::unique_ptr<slam::ScanSource> again = reopen();
          // Each scan deskewed as the first pass placed it (scan_motions.hpp), from its
          // corrected pose.
          const std::unique_ptr<slam::ScanLocator> corrected =
              config.odometry.deskew
                  ? slam::make_replay_locator(loops->corrected, first.scan_motions)
                  : slam::make_given_pose_locator(loops->corrected, false);
          PipelineSettings replay = pipeline;
          replay.refine.reset();
          replay.loops.reset();
          SessionDescription corrected_session = session;
          corrected_session.placement += ", loops closed";
          replayed = run_map_pass(*again, *corrected, replay, config,
                                  {replay_path, info.sensor.name, std::nullopt, true,
                                   corrected_session, &loops->keyframes});
          if (replayed->result.interrupted) throw Interrupted("interrupted");
        });
      } catch (const Interrupted&) {
        replay_interrupted = true;
      } catch (const std::exception& e) {
        // The input changed or went away since the first pass: its map stays.
        spdlog::warn("the second pass failed: {}; the map keeps the odometry's poses", e.what());
        second_pass = std::string("failed (") + e.what() + "): the map keeps the odometry's poses";
        replayed.reset();
      }
      if (replay_interrupted) {
        second_pass = "interrupted: the map keeps the odometry's poses";
        pass.result.interrupted = true;
      } else if (replayed) {
        second_pass = "mapped again with the corrected poses";
        pass = std::move(*replayed);
        second = pass.result;
      }
    }
  }
  const PipelineResult& result = pass.result;
  // The poses the map was made with; with loops closed and no second pass, the corrected ones
  // all the same (to map later with --gt).
  const slam::Trajectory& final_poses =
      continued ? continued->final_poses
                : (loops && loops->corrects_poses() && !second ? loops->corrected : result.poses);
  slam::write_tum(final_poses, (out / "trajectory.tum").string());
  slam::write_kitti(final_poses, (out / "trajectory.kitti").string());

  MapRunSummary summary;
  summary.config = &config;
  summary.input = &info;
  summary.backend = pass.backend;
  summary.backend_reason = pass.backend_reason;
  summary.poses = locator->description() + (pipeline.refine ? ", refined (VGICP)" : "") +
                  (second ? ", loops closed" : "");
  summary.pipeline = &result;
  summary.map = pass.map;
  summary.map_chunks = pass.map_chunks;
  summary.continued_chunks = pass.continued_chunks;
  summary.device_memory_bytes = pass.device_memory_bytes;
  summary.final_flush_ms = pass.final_flush_ms;
  nlohmann::json report = map_report_json(summary);
  if (odometry) {
    const slam::odometry::OdometryCounts counts = odometry->counts();
    report["odometry"] = odometry_json(counts, config.odometry.intensity_fusion);
    if (config.odometry.intensity_fusion && counts.intensity_confirmed_scans < counts.scans) {
      spdlog::warn("intensity fusion {}: edges were taken from the geometry alone",
                   intensity_fusion_text(counts, true));
    }
  }
  if (pipeline.refine) report["refine"] = refine_json(first, *pipeline.refine);
  // Every run that made the map, this one last.
  if (pipeline.integrate && fs::exists(out / "map.h5")) {
    report["sessions"] = sessions_json(out / "map.h5");
  }
  if (continued) report["relocalization"] = continued->report;
  if (loops) {
    report["loops"] = loops_json(*loops, first.timings.loops_finish_ms);
    report["loops"]["second_pass"] = second_pass;
    report["loops"]["first_pass"] = pass_json(first);
    if (second) report["loops"]["second_pass_run"] = pass_json(*second);
  } else if (odometry) {
    report["loops"] = {{"enabled", false}, {"why", no_loops}};
  }
  // Where the poses were estimated and the truth is known, the mesh is also scored in the
  // frame that aligns the two trajectories (evaluate_map_mesh).
  std::optional<Eigen::Isometry3d> T_truth_estimate;
  if (truth && final_poses.size() >= 2) {
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
      if (odometry && spans_plane) T_truth_estimate = final_evaluation.alignment.T;
      // The front end's own poses too, to show what the loops and the refinement changed.
      if (loops && loops->corrects_poses())
        report["eval"]["traj_before_loops"] = evaluate(first.poses);
      if (first.unrefined_poses && first.unrefined_poses->size() >= 2)
        report["eval"]["traj_unrefined"] = evaluate(*first.unrefined_poses);
    } catch (const slam::TrajectoryError& e) {
      spdlog::warn("the trajectory could not be compared with the ground truth: {}", e.what());
    }
  }
  if (!options.no_mesh && !options.poses_only && result.frames_mapped > 0) {
    const MeshErrorOutputs error_outputs{
        out, plan_inputs(options, final_poses, given != nullptr, truth)};
    const MapMesh meshed = mesh_map(out / "map.h5", out, error_outputs.plan);
    report["mesh"] = mesh_json(meshed);
    if (std::optional<nlohmann::json> evaluation =
            evaluate_map_mesh(meshed.mesh, references, T_truth_estimate, &error_outputs)) {
      report["eval"]["mesh"] = *evaluation;
    }
  }
  report["html"] = kReportHtml;
  write_json(report, (out / "report.json").string());
  write_report_html(out, report);

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
  command->add_option("--initial-pose", options->initial_pose,
                      "With --continue and no --gt: where the recording's first scan lies in the "
                      "map, roughly, as x,y,z,yaw_deg (it is still verified)");
  command->add_option("--start", options->start,
                      "First scan to map: a frame index, or seconds after the first scan (12.5s)");
  command->add_option("--end", options->end, "Last scan to map (as --start)");
  command->add_flag("--overwrite", options->overwrite, "Replace OUT/map.h5 if it exists");
  command->add_flag("--no-mesh", options->no_mesh,
                    "Write the map only, no mesh.ply / mesh.glb / topdown.png");
  add_plan_height_option(*command, options->plan_height);
  command->add_flag("--no-loop-closure", options->no_loop_closure,
                    "Map with the odometry's poses alone (loop.enabled false)");
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
