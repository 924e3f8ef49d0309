// featsense bench features / bench odometry: the front end's speed per scan, as JSON. The
// scans are a simulated OS1-128 sequence (noise and motion distortion on, made before the
// clock starts) or the first frames of a recording (--input). `features` times the feature
// extraction alone; `odometry` runs the mapping engine's own front end over each scan in order
// (the odometry locator, with --refine and --loops the map pass's refinement and loop
// stages), times it and gives the trajectory's error where the truth is known. The
// benchmarks themselves live in test/bench/suite; this file holds their options.

#include <algorithm>
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "featsense/bench/front_end_benchmarks.hpp"
#include "json_output.hpp"
#include "simulate_job.hpp"
#include "source_options.hpp"

namespace featsense::app {
namespace {

struct BenchFrontEndOptions {
  std::string scene = "parking";
  std::string path = "drive";
  std::string trajectory_file;            ///< TUM sensor poses for the simulation instead of --path
  bench::OdometryBenchSettings odometry;  ///< bench odometry's own options
  InputOptions input;
  int scans = 100;
  std::optional<std::string> json_path;
};

/// The benchmark's scans: the first --scans of --input, or a simulation of --scene along
/// --path (or --trajectory), made outside the timed stages.
struct OpenedScans {
  std::unique_ptr<slam::PreparedSimulation> simulation;  ///< what the scans refer to: keep it first
  std::unique_ptr<bench::BenchScans> scans;
};

OpenedScans open_scans(const BenchFrontEndOptions& options, const config::Config& config) {
  OpenedScans opened;
  if (!options.input.input.empty()) {
    opened.scans = std::make_unique<bench::BenchScans>(
        options.input.open(config), options.input.input, static_cast<uint64_t>(options.scans));
    return opened;
  }
  SimulateOptions simulate;
  simulate.scene = options.scene;
  simulate.path = options.trajectory_file.empty() ? options.path : "";
  simulate.trajectory_file = options.trajectory_file;
  simulate.frames = options.scans;
  opened.simulation = std::make_unique<slam::PreparedSimulation>(simulation_request(simulate));
  const slam::PreparedSimulation& simulation = *opened.simulation;
  const std::string description =
      "simulated " + options.scene + " scene, " +
      (options.trajectory_file.empty() ? options.path + " path"
                                       : "path " + options.trajectory_file) +
      ", " + simulation.simulator->settings().sensor.name;
  opened.scans = std::make_unique<bench::BenchScans>(
      *simulation.simulator, std::min<uint64_t>(simulation.frames, options.scans),
      simulation.frame_poses(), description);
  return opened;
}

nlohmann::json run_bench_features(const BenchFrontEndOptions& options, const CliContext& context) {
  const config::Config config = context.load_config({});
  OpenedScans opened = open_scans(options, config);
  return bench::bench_features(config, *opened.scans);
}

nlohmann::json run_bench_odometry(const BenchFrontEndOptions& options, const CliContext& context) {
  const config::Config config = context.load_config({});
  OpenedScans opened = open_scans(options, config);
  return bench::bench_odometry(config, *opened.scans, options.odometry);
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
    command->add_option("--trajectory-out", options->odometry.estimate_out,
                        "Write the estimated poses here (TUM)");
    command->add_flag("--refine", options->odometry.refine,
                      "Refine the poses too (refine.*): its ms, and the refined poses' error");
    command->add_option("--refined-out", options->odometry.refined_out,
                        "With --refine: write the refined poses here (TUM)");
    command->add_option("--corrected-out", options->odometry.corrected_out,
                        "With --loops: write the loop-corrected poses here (TUM)");
    command->add_option("--truth-out", options->odometry.truth_out,
                        "Write the simulated truth at the scans' stamps here (TUM)");
    command->add_flag("--wrong-loop", options->odometry.wrong_loop,
                      "With --loops: then add a deliberately wrong loop to the graph and give "
                      "the error of the poses with it (the robust loss at work)");
    command->add_flag("--loops", options->odometry.loops,
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
