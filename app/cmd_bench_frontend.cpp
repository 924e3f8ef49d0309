// featsense bench features / bench odometry: the front end's speed per scan, as JSON. The
// scans are a simulated OS1-128 sequence (noise and motion distortion on, made before the
// clock starts) or the first frames of a recording (--input). `features` times the feature
// extraction alone; `odometry` times extraction and registration of each scan in order, as
// the mapping run does, and gives the trajectory's error where the truth is known.

#include <chrono>
#include <cmath>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/mapping/loop_stage.hpp"
#include "featsense/slam/features/feature_extractor.hpp"
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/odometry/feature_odometry.hpp"
#include "featsense/slam/refine/placement_refiner.hpp"
#include "featsense/slam/refine/refinement_cloud.hpp"
#include "featsense/slam/trajectory/sweep_motion.hpp"
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

/// The map refinement behind the odometry, as the mapping run does it: each scan deskewed
/// with the odometry's motion, the stretches registered as they complete.
class BenchRefinement {
 public:
  explicit BenchRefinement(const config::Config& config)
      : settings_(slam::refine::from_config(config)),
        refiner_(settings_),
        deskew_(config.odometry.deskew) {}

  /// The placements made final by this scan (with their scans' sequence numbers).
  std::vector<slam::ScanPlacement> add(const slam::Scan& scan,
                                       const slam::odometry::OdometryResult& odometry) {
    if (odometry.sweep.moving()) sweep_ = odometry.sweep;
    slam::ScanPlacement placed;
    placed.sequence = scan.sequence;
    placed.stamp_ns = scan.stamp_ns;
    placed.T_map_sensor = odometry.T_map_sensor;
    if (deskew_ && sweep_.moving()) {
      placed.column_T_map_sensor = slam::column_poses(scan, placed.T_map_sensor, [&](double t) {
        return std::optional<Eigen::Isometry3d>(placed.T_map_sensor * sweep_.at(t));
      });
    }
    return take(refiner_.add(scan, std::move(placed)));
  }

  /// The scans still held, refined as a shorter stretch.
  std::vector<slam::ScanPlacement> finish() { return take(refiner_.finish()); }
  const slam::Trajectory& refined() const { return refined_; }

  nlohmann::json json() const {
    const slam::refine::RefineCounts& counts = refiner_.counts();
    // The first scan is a stretch of its own, with nothing to register.
    const double stretches = static_cast<double>(std::max<size_t>(
        counts.refined + counts.not_converged + counts.too_far + counts.worse_fit, 1));
    std::vector<double> stretch_ms, step_m, step_deg;
    double cloud_total_ms = 0.0, stretch_total_ms = 0.0;
    for (const double ms : refiner_.cloud_ms()) cloud_total_ms += ms;
    for (const slam::refine::StretchRegistration& r : counts.stretches) {
      stretch_ms.push_back(r.ms);
      stretch_total_ms += r.ms;
      if (r.outcome != slam::refine::RefineOutcome::refined) continue;
      step_m.push_back(r.step_m);
      step_deg.push_back(r.step_deg);
    }
    return {{"distance_m", settings_.distance_m},
            {"voxel_m", settings_.voxel_m},
            {"stretches", counts.stretches.size()},
            {"scans", counts.scans},
            {"refined", counts.refined},
            {"kept_not_converged", counts.not_converged},
            {"kept_too_far", counts.too_far},
            {"kept_worse_fit", counts.worse_fit},
            {"clouds", refiner_.cloud_ms().size()},
            {"cloud", timing_json(refiner_.cloud_ms())},
            {"registration", timing_json(stretch_ms)},
            // What the refinement costs per scan: its clouds and registrations over the scans.
            {"per_scan_ms", (cloud_total_ms + stretch_total_ms) /
                                static_cast<double>(std::max<size_t>(counts.scans, 1))},
            // A stretch's refinement against the time its scans took to record: above 1 it
            // keeps up with the sensor.
            {"per_stretch_ms", (cloud_total_ms + stretch_total_ms) / stretches},
            {"recorded_per_stretch_ms", recorded_ms() / stretches},
            {"real_time_factor", recorded_ms() / std::max(cloud_total_ms + stretch_total_ms, 1e-9)},
            {"step_m", min_median_max(step_m)},
            {"step_deg", min_median_max(step_deg)}};
  }

 private:
  double recorded_ms() const {
    if (refined_.size() < 2) return 0.0;
    return static_cast<double>(refined_.stamps_ns.back() - refined_.stamps_ns.front()) * 1e-6;
  }

  std::vector<slam::ScanPlacement> take(std::vector<slam::ScanPlacement> placements) {
    for (const slam::ScanPlacement& placement : placements)
      refined_.push_back(placement.stamp_ns, placement.T_map_sensor);
    return placements;
  }

  slam::refine::RefineSettings settings_;
  slam::refine::PlacementRefiner refiner_;
  bool deskew_;
  slam::SweepMotion sweep_;  ///< the last scan's whose stamp advanced
  slam::Trajectory refined_;
};

/// Loop closure over the final poses, as the mapping run does it but in line and timed: the
/// keyframes' clouds, the search, the verification and the solves, and what the loops did to
/// the path.
class BenchLoops {
 public:
  explicit BenchLoops(const config::Config& config)
      : settings_(slam::loops::from_config(config)),
        selector_(settings_.keyframe_distance_m, settings_.keyframe_angle_deg),
        closer_(settings_) {}

  void add(const slam::Scan& scan, const slam::ScanPlacement& placement) {
    const bool keyframe = selector_.next(placement.T_map_sensor);
    path_.push_back(placement.stamp_ns, placement.T_map_sensor);
    travelled_m_.push_back(selector_.travelled_m());
    slam::loops::append_in_time_order(&imu_, scan.imu);
    if (!keyframe) return;
    const auto start = Clock::now();
    const std::vector<Eigen::Vector3f> points =
        slam::refine::voxel_centroids(scan, placement, settings_.cloud_voxel_m);
    cloud_ms_.push_back(ms_since(start));
    closer_.add_keyframe(placement.stamp_ns, selector_.travelled_m(), placement.T_map_sensor,
                         points);
    keyframe_stamps_ns_.push_back(placement.stamp_ns);
  }

  /// The corrected poses of every scan added.
  slam::Trajectory finish() {
    gravity_ = closer_.finish(path_.stamps_ns, path_.poses, imu_).gravity;
    return corrected();
  }

  /// The corrected poses of every scan added, from the graph as it is.
  slam::Trajectory corrected() const {
    return mapping::corrected_path(closer_.correction(), path_, travelled_m_);
  }

  /// A deliberately wrong loop added to the graph (and optimised): the keyframe three
  /// quarters along the path claimed to lie 4 m ahead of the one a quarter along and turned
  /// 30 degrees, as confident as the first true loop. What the claim is off by against the
  /// truth, and the weight the robust loss left it.
  nlohmann::json inject_wrong_loop(const std::optional<slam::Trajectory>& truth) {
    const size_t n = closer_.keyframes();
    if (n < 8) return {{"skipped", "fewer than 8 keyframes"}};
    const size_t from = n / 4, to = 3 * n / 4;
    Eigen::Isometry3d claim = Eigen::Isometry3d::Identity();
    claim.linear() =
        Eigen::AngleAxisd(30.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    claim.translation() = Eigen::Vector3d(4.0, 0.0, 0.0);
    slam::loops::Matrix6d information = slam::loops::Matrix6d::Identity();
    information.diagonal() << 1e4, 1e4, 1e4, 400.0, 400.0, 400.0;  // 0.01 rad, 5 cm
    for (const slam::loops::PoseGraphEdge& edge : closer_.graph().edges()) {
      if (edge.loop) {
        information = edge.information;
        break;
      }
    }
    closer_.add_loop_edge(from, to, claim, information);
    nlohmann::json out = {{"from", from}, {"to", to}, {"weight", closer_.loops().back().weight}};
    const std::optional<Eigen::Isometry3d> a =
        truth ? truth_at(*truth, keyframe_stamps_ns_[from]) : std::nullopt;
    const std::optional<Eigen::Isometry3d> b =
        truth ? truth_at(*truth, keyframe_stamps_ns_[to]) : std::nullopt;
    if (a && b) {
      const Eigen::Isometry3d error = (a->inverse() * *b).inverse() * claim;
      out["claim_error_m"] = error.translation().norm();
      out["claim_error_deg"] = slam::rotation_angle_deg(error.rotation());
    }
    return out;
  }

  /// Counts and times; with the truth, each loop's measured pose against it: a loop more than
  /// 0.3 m or 2 degrees off is false (it would bend the map).
  nlohmann::json json(const std::optional<slam::Trajectory>& truth) const {
    const slam::loops::LoopCounts& counts = closer_.counts();
    nlohmann::json rejected = nlohmann::json::object();
    for (const auto& [reason, count] : counts.rejected) rejected[reason] = count;
    double total_ms = 0.0;
    for (const double ms : counts.keyframe_ms) total_ms += ms;
    for (const double ms : cloud_ms_) total_ms += ms;
    const double recorded_ms =
        path_.size() < 2
            ? 0.0
            : static_cast<double>(path_.stamps_ns.back() - path_.stamps_ns.front()) * 1e-6;
    nlohmann::json out = {{"keyframes", counts.keyframes},
                          {"candidates", counts.candidates},
                          {"verified", counts.verified},
                          {"accepted", closer_.loops().size()},
                          {"rejected", rejected},
                          {"keyframe_clouds_mb", static_cast<double>(counts.cloud_bytes) / 1e6},
                          {"cloud", timing_json(cloud_ms_)},
                          {"keyframe", timing_json(counts.keyframe_ms)},
                          {"optimise", timing_json(counts.optimise_ms)},
                          // The loop closure's time against the recording's: above 1 it
                          // keeps up with the sensor on one core.
                          {"real_time_factor", recorded_ms / std::max(total_ms, 1e-9)},
                          {"gravity_observations", gravity_.observations}};
    if (gravity_.observations > 0) {
      out["gravity_map_tilt_deg"] = {gravity_.map_tilt_deg.x(), gravity_.map_tilt_deg.y()};
      out["gravity_accel_bias_mps2"] = {gravity_.accel_bias_mps2.x(), gravity_.accel_bias_mps2.y(),
                                        gravity_.accel_bias_mps2.z()};
      out["gravity_map_tilt_sigma_deg"] = gravity_.tilt_sigma_deg;
      out["gravity_levelled_deg"] = gravity_.levelled_deg;
      out["gravity_rms_whitened"] = gravity_.rms_whitened;
    }
    if (!truth) return out;
    size_t false_loops = 0;
    double worst_m = 0.0, worst_deg = 0.0;
    size_t k = 0;
    for (const slam::loops::PoseGraphEdge& edge : closer_.graph().edges()) {
      if (!edge.loop) continue;
      ++k;
      const std::optional<Eigen::Isometry3d> from =
          truth_at(*truth, keyframe_stamps_ns_[edge.from]);
      const std::optional<Eigen::Isometry3d> to = truth_at(*truth, keyframe_stamps_ns_[edge.to]);
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

 private:
  static std::optional<Eigen::Isometry3d> truth_at(const slam::Trajectory& truth,
                                                   int64_t stamp_ns) {
    for (size_t i = 0; i < truth.size(); ++i) {
      if (truth.stamps_ns[i] == stamp_ns) return truth.poses[i];
    }
    return std::nullopt;
  }

  slam::loops::LoopSettings settings_;
  slam::loops::KeyframeSelector selector_;
  slam::loops::LoopCloser closer_;
  slam::Trajectory path_;
  std::vector<double> travelled_m_;
  std::vector<double> cloud_ms_;
  std::vector<int64_t> keyframe_stamps_ns_;
  std::vector<slam::ImuSample> imu_;  ///< every scan's, in order
  slam::loops::GravityEstimate gravity_;
};

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

nlohmann::json run_bench_odometry(const BenchFrontEndOptions& options, const CliContext& context) {
  const config::Config config = context.load_config({});
  BenchScans scans(options, config);
  const slam::features::FeatureSettings settings = slam::features::from_config(config);
  slam::odometry::FeatureOdometry odometry(slam::odometry::from_config(config));
  std::optional<BenchRefinement> refinement;
  if (options.refine) refinement.emplace(config);
  std::optional<BenchLoops> loops;
  if (options.loops) loops.emplace(config);
  // With the refinement, the scans wait for their final poses before the loops see them.
  std::deque<slam::Scan> held;
  const auto to_loops = [&](const std::vector<slam::ScanPlacement>& final) {
    for (const slam::ScanPlacement& placement : final) {
      while (!held.empty() && held.front().sequence != placement.sequence) held.pop_front();
      if (held.empty()) continue;
      loops->add(held.front(), placement);
      held.pop_front();
    }
  };

  std::vector<double> features_ms, registration_ms, total_ms, feature_counts;
  std::vector<double> association_ms, solve_ms, map_update_ms;
  double startup_ms = 0.0;
  size_t degenerate = 0, failed = 0;
  slam::Trajectory estimate;
  slam::odometry::OdometryResult last;
  for (size_t i = 0;; ++i) {
    const std::optional<slam::Scan> scan = scans.next();
    if (!scan) break;
    const auto start = Clock::now();
    const slam::FeatureSet found = slam::features::extract_features(*scan, settings);
    const auto extracted = Clock::now();
    const slam::odometry::OdometryResult result = odometry.register_scan(found, scan->imu);
    const double registration = ms_since(extracted);
    const double features = std::chrono::duration<double, std::milli>(extracted - start).count();
    estimate.stamps_ns.push_back(scan->stamp_ns);
    estimate.poses.push_back(result.T_map_sensor);
    if (loops && refinement) held.push_back(*scan);
    if (refinement) {
      const std::vector<slam::ScanPlacement> final = refinement->add(*scan, result);
      if (loops) to_loops(final);
    } else if (loops) {
      slam::ScanPlacement placement;
      placement.sequence = scan->sequence;
      placement.stamp_ns = scan->stamp_ns;
      placement.T_map_sensor = result.T_map_sensor;
      loops->add(*scan, placement);
    }
    last = result;
    if (result.diagnostics.degenerate) ++degenerate;
    if (i > 0 && !result.diagnostics.converged) ++failed;
    // The first scan only starts the map, the second restarts it with the first deskewed once
    // the motion is known (FeatureOdometry): start-up, reported apart.
    if (i < 2) {
      startup_ms += features + registration;
      continue;
    }
    features_ms.push_back(features);
    association_ms.push_back(result.timing.association_ms);
    solve_ms.push_back(result.timing.solve_ms);
    map_update_ms.push_back(result.timing.map_update_ms);
    registration_ms.push_back(registration);
    total_ms.push_back(features + registration);
    feature_counts.push_back(static_cast<double>(found.size()));
  }
  scans.check_read(options.input.input);
  nlohmann::json result = scans.json("odometry");
  result["intensity_fusion"] = settings.intensity_fusion;
  result["timed_scans"] = total_ms.size();
  result["startup_ms"] = startup_ms;
  result["optimization_steps"] = config.odometry.optimization_steps;
  result["deskew"] = config.odometry.deskew;
  result["features"] = timing_json(features_ms);
  result["registration"] = timing_json(registration_ms);
  result["total"] = timing_json(total_ms);
  result["registration_stages_median_ms"] = {
      {"association", summarize_ms(association_ms).median_ms},
      {"solve", summarize_ms(solve_ms).median_ms},
      {"map_update", summarize_ms(map_update_ms).median_ms}};
  result["features_per_scan"] = min_median_max(feature_counts);
  result["degenerate_scans"] = degenerate;
  result["failed_scans"] = failed;
  // The local feature map is bounded (odometry.map_radius): memory stays flat however long
  // the run.
  result["map_points"] = {{"edges", last.map_edges}, {"surfaces", last.map_surfaces}};
  result["peak_rss_mb"] = peak_rss_mb();
  if (!options.estimate_out.empty()) slam::write_tum(estimate, options.estimate_out);
  if (scans.truth()) add_trajectory_error(estimate, *scans.truth(), result);
  if (scans.truth() && !options.truth_out.empty())
    slam::write_tum(*scans.truth(), options.truth_out);
  if (refinement) {
    const std::vector<slam::ScanPlacement> final = refinement->finish();
    if (loops) to_loops(final);
    const slam::Trajectory& refined = refinement->refined();
    if (!options.refined_out.empty()) slam::write_tum(refined, options.refined_out);
    nlohmann::json refine = refinement->json();
    if (scans.truth()) add_trajectory_error(refined, *scans.truth(), refine);
    result["refine"] = refine;
  }
  if (loops) {
    const slam::Trajectory corrected = loops->finish();
    if (!options.corrected_out.empty()) slam::write_tum(corrected, options.corrected_out);
    nlohmann::json closed = loops->json(scans.truth());
    if (scans.truth()) add_trajectory_error(corrected, *scans.truth(), closed);
    if (options.wrong_loop) {
      nlohmann::json wrong = loops->inject_wrong_loop(scans.truth());
      if (scans.truth() && !wrong.contains("skipped")) {
        add_trajectory_error(loops->corrected(), *scans.truth(), wrong);
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
