// featsense bench features / bench odometry: the front end's speed per scan, as JSON. The
// scans are a simulated OS1-128 sequence (noise and motion distortion on, made before the
// clock starts) or the first frames of a recording (--input). `features` times the feature
// extraction alone; `odometry` times extraction and registration of each scan in order, as
// the mapping run does, and gives the trajectory's error where the truth is known.

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/slam/features/feature_extractor.hpp"
#include "featsense/slam/odometry/feature_odometry.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"
#include "json_output.hpp"
#include "simulate_job.hpp"
#include "source_options.hpp"
#include "timing_stats.hpp"

namespace featsense::app {
namespace {

using Clock = std::chrono::steady_clock;

struct BenchFrontEndOptions {
  std::string scene = "parking";
  std::string path = "drive";
  InputOptions input;
  int scans = 100;
  std::optional<std::string> json_path;
};

/// The benchmark's scans, and the truth at their stamps where they were simulated.
struct FrontEndScans {
  std::vector<slam::Scan> scans;
  std::optional<slam::Trajectory> truth;
  std::string description;
};

FrontEndScans load_scans(const BenchFrontEndOptions& options, const config::Config& config) {
  FrontEndScans out;
  if (!options.input.input.empty()) {
    std::unique_ptr<slam::ScanSource> source = options.input.open(config);
    out.description = source->info().format + " " + options.input.input;
    while (static_cast<int>(out.scans.size()) < options.scans) {
      std::optional<slam::Scan> scan = source->next();
      if (!scan) break;
      out.scans.push_back(std::move(*scan));
    }
    if (out.scans.empty()) throw slam::InputError(options.input.input + ": no readable frame");
    return out;
  }
  SimulateOptions simulate;
  simulate.scene = options.scene;
  simulate.path = options.path;
  simulate.frames = options.scans;
  const PreparedSimulation simulation(simulate);
  for (uint64_t frame = 0; frame < simulation.frames; ++frame) {
    slam::SimulatedFrame simulated = simulation.simulator->simulate(frame);
    simulated.scan.sequence = frame;
    out.scans.push_back(std::move(simulated.scan));
  }
  out.truth = simulation.frame_poses();
  out.description = "simulated " + options.scene + " scene, " + options.path + " path, " +
                    simulation.simulator->settings().sensor.name;
  return out;
}

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

nlohmann::json common_json(const char* name, const FrontEndScans& scans,
                           const slam::features::FeatureSettings& settings) {
  const slam::Scan& first = scans.scans.front();
  return {{"benchmark", name},
          {"scans", scans.description},
          {"sequence_scans", scans.scans.size()},
          {"rows", first.rows},
          {"cols", first.cols},
          {"intensity_fusion", settings.intensity_fusion}};
}

nlohmann::json run_bench_features(const BenchFrontEndOptions& options, const CliContext& context) {
  const config::Config config = context.load_config({});
  const FrontEndScans scans = load_scans(options, config);
  const slam::features::FeatureSettings settings = slam::features::from_config(config);
  slam::features::extract_features(scans.scans.front(), settings);  // warm-up: first allocations

  std::vector<double> total, curvature, selection, intensity, edges, surfaces, edges_geometric;
  size_t confirmed = 0;
  for (const slam::Scan& scan : scans.scans) {
    slam::features::FeatureStats stats;
    const auto start = Clock::now();
    slam::features::extract_features(scan, settings, &stats);
    total.push_back(ms_since(start));
    curvature.push_back(stats.curvature_ms);
    selection.push_back(stats.selection_ms);
    intensity.push_back(stats.intensity_ms);
    edges.push_back(static_cast<double>(stats.edges));
    edges_geometric.push_back(static_cast<double>(stats.edges_geometric));
    surfaces.push_back(static_cast<double>(stats.surfaces));
    if (stats.intensity_confirmed) ++confirmed;
  }
  nlohmann::json result = common_json("features", scans, settings);
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

nlohmann::json run_bench_odometry(const BenchFrontEndOptions& options, const CliContext& context) {
  const config::Config config = context.load_config({});
  const FrontEndScans scans = load_scans(options, config);
  const slam::features::FeatureSettings settings = slam::features::from_config(config);
  slam::odometry::FeatureOdometry odometry(slam::odometry::from_config(config));

  std::vector<double> features_ms, registration_ms, total_ms, feature_counts;
  std::vector<double> association_ms, solve_ms, map_update_ms;
  double startup_ms = 0.0;
  size_t degenerate = 0, failed = 0;
  slam::Trajectory estimate;
  for (size_t i = 0; i < scans.scans.size(); ++i) {
    const auto start = Clock::now();
    const slam::FeatureSet found = slam::features::extract_features(scans.scans[i], settings);
    const auto extracted = Clock::now();
    const slam::odometry::OdometryResult result = odometry.register_scan(found);
    const double registration = ms_since(extracted);
    const double features = std::chrono::duration<double, std::milli>(extracted - start).count();
    estimate.stamps_ns.push_back(scans.scans[i].stamp_ns);
    estimate.poses.push_back(result.T_map_sensor);
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
  nlohmann::json result = common_json("odometry", scans, settings);
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
  if (scans.truth && estimate.size() >= 2) {
    const slam::TrajectoryEvaluation e = slam::evaluate_trajectory(estimate, *scans.truth);
    result["ape_rmse_m"] = e.ape.rmse;
    result["rpe_translation_rmse_m"] = e.rpe_translation.rmse;
    result["path_length_m"] = e.ground_truth_length_m;
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
  command->add_option("--input", options->input.input,
                      "Use the first frames of this recording instead");
  command->add_option("--meta", options->input.meta_path, "Ouster metadata JSON for --input");
  command->add_option("--topic", options->input.topic, "Topic of a bag given as --input");
  command
      ->add_option("--scans", options->scans, "Scans of the sequence (of a recording: its first)")
      ->check(CLI::Range(3, 100000))
      ->capture_default_str();
  command->add_option("--json", options->json_path, "Write the JSON here too ('-' = stdout only)");
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
