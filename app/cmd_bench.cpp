// featsense bench: speed figures as JSON. `bench tsdf` integrates realistic OS1-128 scans
// into the local map and reports per-scan times, throughput and memory; `bench mesh` runs
// marching cubes over a furnished 40 x 40 x 15 m hall. The benchmarks themselves live in
// test/bench/suite; this file holds their options.

#include <memory>

#include "commands.hpp"
#include "featsense/bench/map_benchmarks.hpp"
#include "json_output.hpp"
#include "source_options.hpp"

namespace featsense::app {
namespace {

struct BenchTsdfOptions {
  std::optional<std::string> backend;   ///< map.backend
  std::optional<std::string> map_size;  ///< map.size
  std::optional<std::string> voxel;     ///< map.voxel_size
  std::string scene = "indoor";
  InputOptions input;
  int scans = 50;
  int passes = 4;
  std::optional<std::string> json_path;
};

nlohmann::json run_bench_tsdf(const BenchTsdfOptions& options, const CliContext& context) {
  std::vector<config::Override> overrides;
  add_config_override(overrides, kBackendOption, options.backend);
  add_config_override(overrides, kMapSizeOption, options.map_size);
  add_config_override(overrides, kVoxelOption, options.voxel);
  const config::Config config = context.load_config(overrides);
  if (options.input.input.empty()) {
    return bench::bench_tsdf(config, bench::prepare_builtin(options.scene, options.scans),
                             options.passes);
  }
  const std::unique_ptr<slam::ScanSource> source = options.input.open(config);
  return bench::bench_tsdf(config,
                           bench::prepare_recording(*source, options.input.input, options.scans),
                           options.passes);
}

/// bench mesh's --map: the hall's size.
constexpr ConfigOption kHallSizeOption{"--map", "map.size", "XxYxZ", "Hall size, metres", 'x'};

struct BenchMeshOptions {
  std::optional<std::string> map_size;    ///< map.size
  std::optional<std::string> voxel;       ///< map.voxel_size
  std::optional<std::string> truncation;  ///< map.truncation
  int repeat = 7;
  int threads = 0;
  std::optional<std::string> json_path;
};

Command register_bench_mesh(CLI::App& bench, const CliContext& context) {
  auto options = std::make_shared<BenchMeshOptions>();
  CLI::App* mesh = bench.add_subcommand(
      "mesh", "Marching cubes over a furnished hall: ms per run, voxels/s, triangles/s");
  add_config_option(*mesh, kHallSizeOption, options->map_size);
  add_config_option(*mesh, kVoxelOption, options->voxel);
  add_config_option(*mesh, kTruncationOption, options->truncation);
  mesh->add_option("--repeat", options->repeat, "Timed runs")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  mesh->add_option("--threads", options->threads, "Worker threads, 0 = all cores")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  mesh->add_option("--json", options->json_path, "Write the JSON here too ('-' = stdout only)");
  return {mesh, [options, &context] {
            std::vector<config::Override> overrides;
            add_config_override(overrides, kHallSizeOption, options->map_size);
            add_config_override(overrides, kVoxelOption, options->voxel);
            add_config_override(overrides, kTruncationOption, options->truncation);
            const config::MapConfig map = context.load_config(overrides).map;
            print_bench_result(bench::bench_mesh(map, options->repeat, options->threads),
                               options->json_path);
          }};
}

}  // namespace

std::vector<Command> register_bench(CLI::App& app, const CliContext& context) {
  CLI::App* bench = app.add_subcommand("bench", "Speed benchmarks, printed as JSON");
  bench->require_subcommand(1);
  auto options = std::make_shared<BenchTsdfOptions>();
  CLI::App* tsdf = bench->add_subcommand(
      "tsdf", "Integrate OS1-128 scans into the TSDF local map: per-scan ms, points/s, memory");
  add_config_option(*tsdf, kBackendOption, options->backend);
  add_config_option(*tsdf, kMapSizeOption, options->map_size);
  add_config_option(*tsdf, kVoxelOption, options->voxel);
  tsdf->add_option("--scene", options->scene,
                   "Built-in scans: indoor (20 x 20 x 4 m room) or outdoor")
      ->check(CLI::IsMember({"indoor", "outdoor"}))
      ->capture_default_str();
  tsdf->add_option("--input", options->input.input,
                   "Use the frames of this recording instead (at the origin)");
  tsdf->add_option("--meta", options->input.meta_path, "Ouster metadata JSON for --input");
  tsdf->add_option("--scans", options->scans,
                   "Scans of the sequence (10 a second; of a recording: its first frames)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  tsdf->add_option("--passes", options->passes,
                   "Times the whole sequence is integrated, each time into a new map")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  tsdf->add_option("--json", options->json_path, "Write the JSON here too ('-' = stdout only)");
  const Command tsdf_command{tsdf, [options, &context] {
                               print_bench_result(run_bench_tsdf(*options, context),
                                                  options->json_path);
                             }};
  return {tsdf_command, register_bench_mesh(*bench, context)};
}

}  // namespace featsense::app
