// featsense bench: speed figures as JSON. `bench tsdf` integrates realistic OS1-128 scans
// into the local map and reports per-scan times, throughput and memory; `bench mesh` runs
// marching cubes over a furnished 40 x 40 x 15 m hall.

#include <spdlog/spdlog.h>

#include <tbb/task_arena.h>

#include <chrono>
#include <ctime>
#include <sstream>

#include "bench_scans.hpp"
#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/tsdf/integrator.hpp"
#include "json_output.hpp"
#include "source_options.hpp"
#include "synthetic_room_map.hpp"
#include "timing_stats.hpp"

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

  PreparedScans scans = options.input.input.empty()
                            ? prepare_builtin(options.scene, options.scans)
                            : prepare_recording(options.input, config, options.scans);
  const tsdf::TsdfSettings settings = tsdf::TsdfSettings::from_config(config.map, scans.sensor);
  // The map is centred on the middle of the sensor's path, so that it holds the whole
  // sequence without shifting.
  const tsdf::Vec3 first = scans.rays.front().origin(0);
  const tsdf::Vec3 last = scans.rays.back().origin(0);
  const tsdf::Vec3 centre = 0.5f * (first + last);
  std::string why;
  {
    // Warm-up in a map of its own: kernel loading and first-touch page faults stay out of the
    // figures, and the timed passes start from an empty map as a run does.
    auto warm_up = tsdf::make_integrator(config.map.backend, settings, centre, &why);
    warm_up->integrate(scans.rays.front());
  }
  spdlog::info("{}", why);
  // Prepared before an integrator existed, the scans' arrays move into the memory a run's
  // scans get from then on (page-locked where the integrator is CUDA's: tsdf/host_memory.hpp).
  for (tsdf::RayBatch& batch : scans.rays) batch = tsdf::RayBatch(batch);

  // Each pass integrates the sequence in order, every scan once, into a new map: what the
  // integrator does in a run, where a scan meets the map that the scans before it left.
  std::vector<double> times_ms;
  std::vector<double> empty_map_ms;
  std::vector<double> rays;
  std::vector<double> updated;
  std::unique_ptr<tsdf::Integrator> integrator;
  for (int pass = 0; pass < options.passes; ++pass) {
    integrator.reset();  // one map at a time in memory
    integrator = tsdf::make_integrator(config.map.backend, settings, centre, &why);
    for (size_t i = 0; i < scans.rays.size(); ++i) {
      const auto start = std::chrono::steady_clock::now();
      const tsdf::IntegrationStats stats = integrator->integrate(scans.rays[i]);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      // The first scan meets an empty map (and, on a GPU, buffers still to allocate): it is
      // reported on its own, the figures are those of the scans that meet a map.
      if (i == 0) empty_map_ms.push_back(ms);
      if (i == 0 && scans.rays.size() > 1) continue;
      times_ms.push_back(ms);
      rays.push_back(static_cast<double>(stats.rays));
      updated.push_back(static_cast<double>(stats.voxels_updated));
    }
  }
  const TimingSummary t = summarize_ms(times_ms);
  const double points_per_scan =
      static_cast<double>(scans.input_points) / static_cast<double>(scans.rays.size());
  const nlohmann::json updated_summary = min_median_max(updated);
  const double voxels_median = updated_summary["median"].get<double>();
  // The least memory traffic a scan needs: the points uploaded (end point and origin, 12 bytes
  // each) and, per updated voxel, the candidate written, read and reset and the voxel read and
  // written (5 x 4 bytes). Divided by the GPU's bandwidth it gives the floor of the time.
  const double bytes_per_scan = points_per_scan * 24.0 + voxels_median * 20.0;
  const tsdf::Index3 dim = settings.map_dim();
  nlohmann::json result = {
      {"benchmark", "tsdf"},
      {"backend", integrator->backend_name()},
      {"backend_reason", why},
      {"scans", scans.description},
      {"map_size_m", config.map.size_m},
      {"map_voxels", {dim.x, dim.y, dim.z}},
      {"voxel_size_m", config.map.voxel_size_m},
      {"truncation_m", settings.truncation_m},
      {"interpolation_slope", settings.interpolation_slope},
      {"timed_scans", t.count},
      {"passes", options.passes},
      {"sequence_scans", scans.rays.size()},
      {"empty_map_ms", summarize_ms(empty_map_ms).median_ms},
      {"median_ms", t.median_ms},
      {"p95_ms", t.p95_ms},
      {"max_ms", t.max_ms},
      {"mean_ms", t.mean_ms},
      {"points_per_scan", points_per_scan},
      {"points_per_s", t.median_ms > 0.0 ? points_per_scan / (t.median_ms * 1e-3) : 0.0},
      {"rays_per_scan", min_median_max(rays)},
      {"voxels_updated_per_scan", updated_summary},
      {"min_bytes_per_scan", bytes_per_scan},
      {"memory_bytes", integrator->memory_bytes()}};
  return result;
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

nlohmann::json run_bench_mesh(const BenchMeshOptions& options, const CliContext& context) {
  std::vector<config::Override> overrides;
  add_config_override(overrides, kHallSizeOption, options.map_size);
  add_config_override(overrides, kVoxelOption, options.voxel);
  add_config_override(overrides, kTruncationOption, options.truncation);
  const config::MapConfig map = context.load_config(overrides).map;
  const auto build_start = std::chrono::steady_clock::now();
  storage::MemoryChunkStore store =
      make_room_map(Eigen::Vector3d(map.size_m[0], map.size_m[1], map.size_m[2]), map.voxel_size_m,
                    map.truncation_m);
  const double build_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
  mesh::MeshingSettings settings;
  settings.threads = options.threads;

  mesh::MeshingStats stats;
  mesh::extract_mesh(store, settings, &stats);  // warm-up: first-touch page faults
  std::vector<double> times_ms;
  std::vector<double> cpu_ms;  // all threads: tells the cost apart from a busy machine's waits
  for (int i = 0; i < options.repeat; ++i) {
    const std::clock_t cpu_start = std::clock();
    mesh::extract_mesh(store, settings, &stats);
    cpu_ms.push_back(1e3 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC);
    times_ms.push_back(stats.seconds * 1e3);
  }
  const TimingSummary t = summarize_ms(times_ms);
  const double median_s = t.median_ms * 1e-3;
  const int threads =
      settings.threads > 0 ? settings.threads : tbb::this_task_arena::max_concurrency();
  return {
      {"benchmark", "mesh"},
      {"map", "synthetic furnished hall (exact TSDF, free space observed)"},
      {"map_size_m", map.size_m},
      {"voxel_size_m", map.voxel_size_m},
      {"truncation_m", map.truncation_m},
      {"map_build_s", build_s},
      {"threads", threads},
      {"runs", t.count},
      {"median_ms", t.median_ms},
      {"p95_ms", t.p95_ms},
      {"max_ms", t.max_ms},
      {"mean_ms", t.mean_ms},
      {"cpu_ms", summarize_ms(cpu_ms).median_ms},
      {"chunks", stats.chunks},
      {"voxels", stats.voxels},
      {"triangles", stats.triangles},
      {"vertices", stats.vertices},
      {"voxels_per_s", median_s > 0.0 ? static_cast<double>(stats.voxels) / median_s : 0.0},
      {"triangles_per_s", median_s > 0.0 ? static_cast<double>(stats.triangles) / median_s : 0.0}};
}

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
            print_bench_result(run_bench_mesh(*options, context), options->json_path);
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
