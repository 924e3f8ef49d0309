// featsense bench store: moving a full local map through the HDF5 store (the benchmark:
// test/bench/suite/src/store_bench.cpp).

#include <memory>

#include "commands.hpp"
#include "featsense/bench/map_benchmarks.hpp"
#include "json_output.hpp"

namespace featsense::app {
namespace {

struct BenchStoreOptions {
  std::optional<std::string> backend;   ///< map.backend
  std::optional<std::string> map_size;  ///< map.size
  std::optional<std::string> voxel;     ///< map.voxel_size
  bench::StoreBenchSettings store;
  std::optional<std::string> json_path;
};

}  // namespace

Command register_bench_store(CLI::App& bench, const CliContext& context) {
  auto options = std::make_shared<BenchStoreOptions>();
  CLI::App* command = bench.add_subcommand(
      "store", "Move a full local map through the HDF5 store: ms per shift (spill + load)");
  add_config_option(*command, kBackendOption, options->backend);
  add_config_option(*command, kMapSizeOption, options->map_size);
  add_config_option(*command, kVoxelOption, options->voxel);
  command->add_option("--shift", options->store.shift_m, "Distance of each move, metres")
      ->check(CLI::Range(0.5, 1000.0))
      ->capture_default_str();
  command->add_option("--scans", options->store.scans, "Outdoor scans integrated first")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  command->add_option("--repeat", options->store.repeat, "Timed moves (out and back alternately)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  command->add_option("--dir", options->store.dir,
                      "Folder for the store (default: the temp folder)");
  command->add_option("--json", options->json_path, "Write the JSON here too ('-' = stdout only)");
  return {command, [options, &context] {
            std::vector<config::Override> overrides;
            add_config_override(overrides, kBackendOption, options->backend);
            add_config_override(overrides, kMapSizeOption, options->map_size);
            add_config_override(overrides, kVoxelOption, options->voxel);
            print_bench_result(bench::bench_store(context.load_config(overrides), options->store),
                               options->json_path);
          }};
}

}  // namespace featsense::app
