// featsense bench features / bench odometry: the front end's speed per scan, as JSON. The
// scans are a simulated OS1-128 sequence (noise and motion distortion on, made before the
// clock starts) or the first frames of a recording (--input). `features` times the feature
// extraction alone; `odometry` runs the mapping engine's own front end over each scan in order
// (the odometry locator, with --refine and --loops the map pass's refinement and loop
// stages), times it and gives the trajectory's error where the truth is known.

#include <chrono>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/mapping/loop_stage.hpp"
#include "featsense/mapping/map_pass.hpp"
#include "featsense/slam/features/feature_extractor.hpp"
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/odometry/odometry_locator.hpp"
#include "featsense/slam/refine/placement_refiner.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"
#include "json_output.hpp"
#include "map_report.hpp"
#include "simulate_job.hpp"
#include "source_options.hpp"
#include "timing_stats.hpp"

namespace featsense::app {
namespace {

using Clock = std::chrono::steady_clock;

struct BenchFrontEndOptions {
  std::string scene = "parking";
  std::string path = "drive";
  std::string trajectory_file;  ///< TUM sensor poses for the simulation instead of --path
  std::string estimate_out;     ///< bench odometry: the estimated poses, TUM
  bool refine = false;          ///< bench odometry: the map refinement too (refine.*)
  std::string refined_out;      ///< bench odometry --refine: the refined poses, TUM
  bool loops = false;           ///< bench odometry: loop closure over the final poses (loop.*)
  std::string corrected_out;    ///< bench odometry --loops: the corrected poses, TUM
  std::string truth_out;        ///< bench odometry: the simulated truth, TUM
  bool wrong_loop = false;      ///< bench odometry --loops: a wrong loop injected at the end
  InputOptions input;
  int scans = 100;
  std::optional<std::string> json_path;
};

/// The benchmark's scans, one at a time: a recording's, or a simulation's made frame by frame
/// outside the timed stages, so that a long sequence needs no memory of its own (the peak
/// RSS is the front end's). The truth at their stamps where they were simulated.
class BenchScans {
 public:
  BenchScans(const BenchFrontEndOptions& options, const config::Config& config)
      : limit_(static_cast<uint64_t>(options.scans)) {
    if (!options.input.input.empty()) {
      recording_ = options.input.open(config);
      description_ = recording_->info().format + " " + options.input.input;
      return;
    }
    SimulateOptions simulate;
    simulate.scene = options.scene;
    simulate.path = options.trajectory_file.empty() ? options.path : "";
    simulate.trajectory_file = options.trajectory_file;
    simulate.frames = options.scans;
    simulation_ = std::make_unique<PreparedSimulation>(simulate);
    truth_ = simulation_->frame_poses();
    description_ = "simulated " + options.scene + " scene, " +
                   (options.trajectory_file.empty() ? options.path + " path"
                                                    : "path " + options.trajectory_file) +
                   ", " + simulation_->simulator->settings().sensor.name;
  }

  std::optional<slam::Scan> next() {
    if (count_ >= limit_) return std::nullopt;
    std::optional<slam::Scan> scan;
    if (recording_) {
      scan = recording_->next();
    } else if (count_ < simulation_->frames) {
      scan = std::move(simulation_->simulator->simulate(count_).scan);
      scan->sequence = count_;
    }
    if (!scan) return std::nullopt;
    if (count_ == 0) {
      rows_ = scan->rows;
      cols_ = scan->cols;
    }
    ++count_;
    return scan;
  }

  /// Throws InputError when the source gave no scan at all.
  void check_read(const std::string& input) const {
    if (count_ == 0) throw slam::InputError(input + ": no readable frame");
  }

  const std::optional<slam::Trajectory>& truth() const { return truth_; }

  nlohmann::json json(const char* benchmark) const {
    return {{"benchmark", benchmark},
            {"scans", description_},
            {"sequence_scans", count_},
            {"rows", rows_},
            {"cols", cols_}};
  }

 private:
  std::unique_ptr<slam::ScanSource> recording_;
  std::unique_ptr<PreparedSimulation> simulation_;
  std::optional<slam::Trajectory> truth_;
  std::string description_;
  uint64_t limit_;
  uint64_t count_ = 0;
  int rows_ = 0;
  int cols_ = 0;
};

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

nlohmann::json run_bench_features(const BenchFrontEndOptions& options, const CliContext& context) {
  const config::Config config = context.load_config({});
  BenchScans scans(options, config);
  const slam::features::FeatureSettings settings = slam::features::from_config(config);

  std::vector<double> total, curvature, selection, intensity, edges, surfaces, edges_geometric;
  size_t confirmed = 0;
  bool warmed_up = false;
  while (const std::optional<slam::Scan> scan = scans.next()) {
    // The first scan warms up (the first allocations) and is extracted twice.
    if (!warmed_up) slam::features::extract_features(*scan, settings);
    warmed_up = true;
    slam::features::FeatureStats stats;
    const auto start = Clock::now();
    slam::features::extract_features(*scan, settings, &stats);
    total.push_back(ms_since(start));
    curvature.push_back(stats.curvature_ms);
    selection.push_back(stats.selection_ms);
    intensity.push_back(stats.intensity_ms);
    edges.push_back(static_cast<double>(stats.edges));
    edges_geometric.push_back(static_cast<double>(stats.edges_geometric));
    surfaces.push_back(static_cast<double>(stats.surfaces));
    if (stats.intensity_confirmed) ++confirmed;
  }
  scans.check_read(options.input.input);
  nlohmann::json result = scans.json("features");
  result["intensity_fusion"] = settings.intensity_fusion;
  result.update(timing_json(total));
  result["stages_median_ms"] = {{"curvature", summarize_ms(curvature).median_ms},
                                {"selection", summarize_ms(selection).median_ms},
                                {"intensity", summarize_ms(intensity).median_ms}};
  result["edges_per_scan"] = min_median_max(edges);
  result["geometric_edges_per_scan"] = min_median_max(edges_geometric);
  result["surfaces_per_scan"] = min_median_max(surfaces);
  result["intensity_confirmed_scans"] = confirmed;
  return result;
}

/// The trajectory's error against the truth, as JSON (nothing where it is undetermined).
void add_trajectory_error(const slam::Trajectory& estimate, const slam::Trajectory& truth,
                          nlohmann::json& out) {
  if (estimate.size() < 2) return;
  try {
    const slam::TrajectoryEvaluation e = slam::evaluate_trajectory(estimate, truth);
    out["ape_rmse_m"] = e.ape.rmse;
    out["rpe_translation_rmse_m"] = e.rpe_translation.rmse;
    out["path_length_m"] = e.ground_truth_length_m;
    if (e.kitti) out["kitti_translation_drift_percent"] = e.kitti->t_err_pct;
  } catch (const slam::TrajectoryError& e) {
    // A straight path leaves the alignment undetermined: no figures, and why.
    out["trajectory_evaluation_error"] = e.what();
  }
}

/// The refinement's figures: stretches, what was kept and why, its cost per scan and per
/// stretch against the time the stretch took to record, the corrections.
nlohmann::json bench_refine_json(const mapping::PassResult& run,
                                 const slam::refine::RefineSettings& settings) {
  const slam::refine::RefineCounts& counts = run.refine;
  // The first scan is a stretch of its own, with nothing to register.
  const double stretches = static_cast<double>(std::max<size_t>(
      counts.refined + counts.not_converged + counts.too_far + counts.worse_fit, 1));
  std::vector<double> stretch_ms, step_m, step_deg;
  double cloud_total_ms = 0.0, stretch_total_ms = 0.0;
  for (const double ms : run.refine_cloud_ms) cloud_total_ms += ms;
  for (const slam::refine::StretchRegistration& r : counts.stretches) {
    stretch_ms.push_back(r.ms);
    stretch_total_ms += r.ms;
    if (r.outcome != slam::refine::RefineOutcome::refined) continue;
    step_m.push_back(r.step_m);
    step_deg.push_back(r.step_deg);
  }
  const slam::Trajectory& refined = run.poses;
  const double recorded_ms =
      refined.size() < 2
          ? 0.0
          : static_cast<double>(refined.stamps_ns.back() - refined.stamps_ns.front()) * 1e-6;
  const double total_ms = cloud_total_ms + stretch_total_ms;
  return {{"distance_m", settings.distance_m},
          {"voxel_m", settings.voxel_m},
          {"stretches", counts.stretches.size()},
          {"scans", counts.scans},
          {"refined", counts.refined},
          {"kept_not_converged", counts.not_converged},
          {"kept_too_far", counts.too_far},
          {"kept_worse_fit", counts.worse_fit},
          {"clouds", run.refine_cloud_ms.size()},
          {"cloud", timing_json(run.refine_cloud_ms)},
          {"registration", timing_json(stretch_ms)},
          // What the refinement costs per scan: its clouds and registrations over the scans.
          {"per_scan_ms", total_ms / static_cast<double>(std::max<size_t>(counts.scans, 1))},
          // A stretch's refinement against the time its scans took to record: above 1 it keeps
          // up with the sensor.
          {"per_stretch_ms", total_ms / stretches},
          {"recorded_per_stretch_ms", recorded_ms / stretches},
          {"real_time_factor", recorded_ms / std::max(total_ms, 1e-9)},
          {"step_m", min_median_max(step_m)},
          {"step_deg", min_median_max(step_deg)}};
}

std::optional<Eigen::Isometry3d> truth_at(const slam::Trajectory& truth, int64_t stamp_ns) {
  for (size_t i = 0; i < truth.size(); ++i) {
    if (truth.stamps_ns[i] == stamp_ns) return truth.poses[i];
  }
  return std::nullopt;
}

/// The loop closure's figures: counts and times; with the truth, each loop's measured pose
/// against it: a loop more than 0.3 m or 2 degrees off is false (it would bend the map).
nlohmann::json bench_loops_json(const mapping::LoopOutcome& outcome,
                                const slam::loops::LoopCloser& closer,
                                const std::optional<slam::Trajectory>& truth) {
  const slam::loops::LoopCounts& counts = outcome.counts;
  nlohmann::json rejected = nlohmann::json::object();
  for (const auto& [reason, count] : counts.rejected) rejected[reason] = count;
  double total_ms = 0.0;
  for (const double ms : counts.keyframe_ms) total_ms += ms;
  for (const double ms : outcome.keyframe_cloud_ms) total_ms += ms;
  const slam::Trajectory& path = outcome.before;
  const double recorded_ms =
      path.size() < 2 ? 0.0
                      : static_cast<double>(path.stamps_ns.back() - path.stamps_ns.front()) * 1e-6;
  const slam::loops::GravityEstimate& gravity = outcome.gravity;
  nlohmann::json out = {{"keyframes", counts.keyframes},
                        {"candidates", counts.candidates},
                        {"verified", counts.verified},
                        {"accepted", outcome.loops.size()},
                        {"rejected", rejected},
                        {"keyframe_clouds_mb", static_cast<double>(counts.cloud_bytes) / 1e6},
                        {"cloud", timing_json(outcome.keyframe_cloud_ms)},
                        {"keyframe", timing_json(counts.keyframe_ms)},
                        {"optimise", timing_json(counts.optimise_ms)},
                        // The loop closure's time against the recording's: above 1 it keeps up
                        // with the sensor on one core.
                        {"real_time_factor", recorded_ms / std::max(total_ms, 1e-9)},
                        {"gravity_observations", gravity.observations}};
  if (gravity.observations > 0) {
    out["gravity_map_tilt_deg"] = {gravity.map_tilt_deg.x(), gravity.map_tilt_deg.y()};
    out["gravity_accel_bias_mps2"] = {gravity.accel_bias_mps2.x(), gravity.accel_bias_mps2.y(),
                                      gravity.accel_bias_mps2.z()};
    out["gravity_map_tilt_sigma_deg"] = gravity.tilt_sigma_deg;
    out["gravity_levelled_deg"] = gravity.levelled_deg;
    out["gravity_rms_whitened"] = gravity.rms_whitened;
  }
  if (!truth) return out;
  const std::vector<slam::loops::KeyframeRecord> keyframes = closer.keyframe_records();
  size_t false_loops = 0;
  double worst_m = 0.0, worst_deg = 0.0;
  for (const slam::loops::PoseGraphEdge& edge : closer.graph().edges()) {
    if (!edge.loop) continue;
    const std::optional<Eigen::Isometry3d> from = truth_at(*truth, keyframes[edge.from].stamp_ns);
    const std::optional<Eigen::Isometry3d> to = truth_at(*truth, keyframes[edge.to].stamp_ns);
    if (!from || !to) continue;
    const Eigen::Isometry3d error = (from->inverse() * *to).inverse() * edge.T_from_to;
    const double m = error.translation().norm();
    const double deg = slam::rotation_angle_deg(error.rotation());
    worst_m = std::max(worst_m, m);
    worst_deg = std::max(worst_deg, deg);
    if (m > 0.3 || deg > 2.0) ++false_loops;
  }
  out["false_loops"] = false_loops;
  out["worst_loop_error_m"] = worst_m;
  out["worst_loop_error_deg"] = worst_deg;
  return out;
}

/// A deliberately wrong loop added to the finished graph (and optimised): the keyframe three
/// quarters along the path claimed to lie 4 m ahead of the one a quarter along and turned 30
/// degrees, as confident as the first true loop. What the claim is off by against the truth,
/// and the weight the robust loss left it.
nlohmann::json inject_wrong_loop(slam::loops::LoopCloser& closer,
                                 const std::optional<slam::Trajectory>& truth) {
  const size_t n = closer.keyframes();
  if (n < 8) return {{"skipped", "fewer than 8 keyframes"}};
  const size_t from = n / 4, to = 3 * n / 4;
  Eigen::Isometry3d claim = Eigen::Isometry3d::Identity();
  claim.linear() =
      Eigen::AngleAxisd(30.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  claim.translation() = Eigen::Vector3d(4.0, 0.0, 0.0);
  slam::loops::Matrix6d information = slam::loops::Matrix6d::Identity();
  information.diagonal() << 1e4, 1e4, 1e4, 400.0, 400.0, 400.0;  // 0.01 rad, 5 cm
  for (const slam::loops::PoseGraphEdge& edge : closer.graph().edges()) {
    if (edge.loop) {
      information = edge.information;
      break;
    }
  }
  const std::vector<slam::loops::KeyframeRecord> keyframes = closer.keyframe_records();
  closer.add_loop_edge(from, to, claim, information);
  nlohmann::json out = {{"from", from}, {"to", to}, {"weight", closer.loops().back().weight}};
  const std::optional<Eigen::Isometry3d> a =
      truth ? truth_at(*truth, keyframes[from].stamp_ns) : std::nullopt;
  const std::optional<Eigen::Isometry3d> b =
      truth ? truth_at(*truth, keyframes[to].stamp_ns) : std::nullopt;
  if (a && b) {
    const Eigen::Isometry3d error = (a->inverse() * *b).inverse() * claim;
    out["claim_error_m"] = error.translation().norm();
    out["claim_error_deg"] = slam::rotation_angle_deg(error.rotation());
  }
  return out;
}

/// The odometry's own figures, from the product's locator: per-stage times of every scan
/// after the first two (which start the map), features per scan, degenerate and failed scans.
void add_odometry_figures(const slam::odometry::OdometryCounts& counts, nlohmann::json& result) {
  std::vector<double> features, registration, total, association, solve, map_update, found;
  double startup_ms = 0.0;
  for (size_t i = 0; i < counts.features_ms.size(); ++i) {
    // The first scan only starts the map, the second restarts it with the first deskewed once
    // the motion is known (FeatureOdometry): start-up, reported apart.
    if (i < 2) {
      startup_ms += counts.features_ms[i] + counts.registration_ms[i];
      continue;
    }
    features.push_back(counts.features_ms[i]);
    registration.push_back(counts.registration_ms[i]);
    total.push_back(counts.features_ms[i] + counts.registration_ms[i]);
    association.push_back(counts.association_ms[i]);
    solve.push_back(counts.solve_ms[i]);
    map_update.push_back(counts.map_update_ms[i]);
    found.push_back(counts.features_per_scan[i]);
  }
  result["timed_scans"] = total.size();
  result["startup_ms"] = startup_ms;
  result["features"] = timing_json(features);
  result["registration"] = timing_json(registration);
  result["total"] = timing_json(total);
  result["registration_stages_median_ms"] = {{"association", summarize_ms(association).median_ms},
                                             {"solve", summarize_ms(solve).median_ms},
                                             {"map_update", summarize_ms(map_update).median_ms}};
  result["features_per_scan"] = min_median_max(found);
  result["degenerate_scans"] = counts.degenerate_scans;
  result["failed_scans"] = counts.failed_scans;
  // The local feature map is bounded (odometry.map_radius): memory stays flat however long
  // the run.
  result["map_points"] = {{"edges", counts.map_edges}, {"surfaces", counts.map_surfaces}};
}

/// The front end as `featsense map` runs it, poses only, one scan at a time: the product's
/// odometry locator, and with --refine / --loops the map pass's own refinement and loop
/// stages (slam/mapping). The scans are simulated outside the clock.
nlohmann::json run_bench_odometry(const BenchFrontEndOptions& options, const CliContext& context) {
  config::Config config = context.load_config({});
  BenchScans scans(options, config);
  const std::unique_ptr<slam::odometry::OdometryLocator> odometry =
      slam::odometry::make_odometry_locator(config);
  mapping::PassSettings stages;
  stages.integrate = false;
  stages.drop_mixed_pixels = config.sensor.drop_mixed_pixels;
  if (options.refine) stages.refine = slam::refine::from_config(config);
  if (options.loops) stages.loops = slam::loops::from_config(config);
  mapping::MapPass pass(*odometry, stages, config, config::SensorModel{}, {}, {});
  slam::Trajectory estimate;  // the odometry's poses, before the refinement
  const auto map_final = [&pass](std::vector<mapping::PlacedScan> final) {
    for (mapping::PlacedScan& scan : final) {
      if (std::optional<mapping::LocatedScan> located = pass.make_rays(std::move(scan)))
        pass.integrate(std::move(*located));
    }
  };
  while (std::optional<slam::Scan> scan = scans.next()) {
    pass.count_read();
    std::optional<mapping::PlacedScan> placed = pass.locate(std::move(*scan));
    if (!placed) continue;
    estimate.push_back(placed->placement.stamp_ns, placed->placement.T_map_sensor);
    map_final(pass.refine(std::move(*placed)));
  }
  map_final(pass.finish_refinement());
  scans.check_read(options.input.input);
  const mapping::PassResult run = pass.close();

  nlohmann::json result = scans.json("odometry");
  result["intensity_fusion"] = config.odometry.intensity_fusion;
  result["optimization_steps"] = config.odometry.optimization_steps;
  result["deskew"] = config.odometry.deskew;
  add_odometry_figures(odometry->counts(), result);
  result["peak_rss_mb"] = peak_rss_mb();
  const std::optional<slam::Trajectory>& truth = scans.truth();
  if (!options.estimate_out.empty()) slam::write_tum(estimate, options.estimate_out);
  if (truth) add_trajectory_error(estimate, *truth, result);
  if (truth && !options.truth_out.empty()) slam::write_tum(*truth, options.truth_out);
  if (stages.refine) {
    if (!options.refined_out.empty()) slam::write_tum(run.poses, options.refined_out);
    nlohmann::json refine = bench_refine_json(run, *stages.refine);
    if (truth) add_trajectory_error(run.poses, *truth, refine);
    result["refine"] = refine;
  }
  if (run.loops) {
    mapping::LoopStage& stage = *pass.loop_stage();
    if (!options.corrected_out.empty())
      slam::write_tum(run.loops->corrected, options.corrected_out);
    nlohmann::json closed = bench_loops_json(*run.loops, stage.closer_after_finish(), truth);
    if (truth) add_trajectory_error(run.loops->corrected, *truth, closed);
    if (options.wrong_loop) {
      nlohmann::json wrong = inject_wrong_loop(stage.closer_after_finish(), truth);
      if (truth && !wrong.contains("skipped")) {
        add_trajectory_error(stage.corrected(), *truth, wrong);
        if (closed.contains("ape_rmse_m") && wrong.contains("ape_rmse_m"))
          wrong["ape_ratio"] = wrong["ape_rmse_m"].get<double>() /
                               std::max(closed["ape_rmse_m"].get<double>(), 1e-12);
      }
      closed["wrong_loop"] = wrong;
    }
    result["loops"] = closed;
  }
  return result;
}

Command add_front_end_bench(CLI::App& bench, const char* name, const char* help,
                            nlohmann::json (*run)(const BenchFrontEndOptions&, const CliContext&),
                            const CliContext& context) {
  auto options = std::make_shared<BenchFrontEndOptions>();
  CLI::App* command = bench.add_subcommand(name, help);
  command->add_option("--scene", options->scene, "Simulated scene (see `featsense simulate`)")
      ->capture_default_str();
  command->add_option("--path", options->path, "Simulated path (see `featsense simulate`)")
      ->capture_default_str();
  command
      ->add_option("--trajectory", options->trajectory_file,
                   "TUM file of sensor poses to simulate instead of --path")
      ->check(CLI::ExistingFile);
  command->add_option("--input", options->input.input,
                      "Use the first frames of this recording instead");
  command->add_option("--meta", options->input.meta_path, "Ouster metadata JSON for --input");
  command->add_option("--topic", options->input.topic, "Topic of a bag given as --input");
  command
      ->add_option("--scans", options->scans, "Scans of the sequence (of a recording: its first)")
      ->check(CLI::Range(3, 100000))
      ->capture_default_str();
  command->add_option("--json", options->json_path, "Write the JSON here too ('-' = stdout only)");
  if (std::string(name) == "odometry") {
    command->add_option("--trajectory-out", options->estimate_out,
                        "Write the estimated poses here (TUM)");
    command->add_flag("--refine", options->refine,
                      "Refine the poses too (refine.*): its ms, and the refined poses' error");
    command->add_option("--refined-out", options->refined_out,
                        "With --refine: write the refined poses here (TUM)");
    command->add_option("--corrected-out", options->corrected_out,
                        "With --loops: write the loop-corrected poses here (TUM)");
    command->add_option("--truth-out", options->truth_out,
                        "Write the simulated truth at the scans' stamps here (TUM)");
    command->add_flag("--wrong-loop", options->wrong_loop,
                      "With --loops: then add a deliberately wrong loop to the graph and give "
                      "the error of the poses with it (the robust loss at work)");
    command->add_flag("--loops", options->loops,
                      "Close loops over the final poses (loop.*): ms per keyframe, the loops, "
                      "false ones against the truth, the corrected poses' error");
  }
  return {command, [options, run, &context] {
            print_bench_result(run(*options, context), options->json_path);
          }};
}

}  // namespace

std::vector<Command> register_bench_front_end(CLI::App& bench, const CliContext& context) {
  return {add_front_end_bench(bench, "features",
                              "Feature extraction per scan: median / p95 ms, features per scan",
                              run_bench_features, context),
          add_front_end_bench(bench, "odometry",
                              "Features and registration per scan, in order: ms, and the "
                              "trajectory's error where it was simulated",
                              run_bench_odometry, context)};
}

}  // namespace featsense::app
