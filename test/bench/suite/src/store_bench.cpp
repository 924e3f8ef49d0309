// featsense bench store: moving a full local map through the HDF5 store. A map is filled
// with outdoor OS1-128 scans (free space carved, so most of it is observed), then moved back
// and forth by --shift metres: each move spills the slab that leaves into the store's chunks
// and loads the slab that enters (the move back loads what the move out spilled).

#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>

#include "featsense/bench/map_benchmarks.hpp"
#include "featsense/bench/measurements.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/storage/shifting_map.hpp"
#include "featsense/tsdf/integrator.hpp"

namespace featsense::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

nlohmann::json bench_store(const config::Config& config, const StoreBenchSettings& options) {
  const PreparedScans scans = prepare_builtin("outdoor", options.scans);
  const tsdf::TsdfSettings settings = tsdf::TsdfSettings::from_config(config.map, scans.sensor);
  std::string why;
  auto integrator =
      tsdf::make_integrator(config.map.backend, settings, scans.rays.front().origin(0), &why);
  spdlog::info("{}", why);
  for (const tsdf::RayBatch& rays : scans.rays) integrator->integrate(rays);

  const fs::path dir = options.dir.empty() ? fs::temp_directory_path() / "featsense-bench-store"
                                           : fs::path(options.dir);
  fs::create_directories(dir);
  const fs::path path = dir / "bench.h5";
  storage::MapMetadata metadata;
  metadata.voxel_size_m = config.map.voxel_size_m;
  metadata.truncation_m = config.map.truncation_m;
  metadata.max_weight = config.map.max_weight;
  metadata.sensor = scans.sensor.name;
  storage::Hdf5ChunkStore store(path, storage::OpenMode::kCreateOverwrite, metadata);
  storage::ShiftingMap map(*integrator, store, config.map.shift_threshold_m);

  const tsdf::Index3 home = integrator->geometry().origin;
  const int32_t shift_voxels = static_cast<int32_t>(std::lround(
                                   options.shift_m / config.map.voxel_size_m / tsdf::kBrickSize)) *
                               tsdf::kBrickSize;
  std::vector<double> shift_ms;
  std::vector<double> bricks;
  for (int i = 0; i < options.repeat; ++i) {
    const tsdf::Index3 target =
        i % 2 == 0 ? tsdf::Index3{home.x + shift_voxels, home.y, home.z} : home;
    const size_t spilled_before = map.stats().bricks_spilled;
    const Clock::time_point start = Clock::now();
    map.move_to(target);
    shift_ms.push_back(seconds_since(start) * 1e3);
    bricks.push_back(static_cast<double>(map.stats().bricks_spilled - spilled_before));
  }
  Clock::time_point start = Clock::now();
  store.flush();
  const double flush_s = seconds_since(start);
  start = Clock::now();
  map.sync();
  const double sync_s = seconds_since(start);
  const size_t chunks = store.keys().size();
  start = Clock::now();
  store.close();
  const double close_s = seconds_since(start);

  const TimingSummary t = summarize_ms(shift_ms);
  const double slab_mb =
      min_median_max(bricks)["median"].get<double>() * tsdf::kBrickVoxels * sizeof(uint32_t) / 1e6;
  nlohmann::json result = {
      {"benchmark", "store"},
      {"backend", integrator->backend_name()},
      {"backend_reason", why},
      {"map_size_m", config.map.size_m},
      {"voxel_size_m", config.map.voxel_size_m},
      {"shift_m", shift_voxels * config.map.voxel_size_m},
      {"timed_shifts", t.count},
      {"median_ms", t.median_ms},
      {"p95_ms", t.p95_ms},
      {"max_ms", t.max_ms},
      {"slab_mb", slab_mb},
      {"slab_mb_per_s", t.median_ms > 0.0 ? 2.0 * slab_mb / (t.median_ms * 1e-3) : 0.0},
      {"bricks_per_shift", min_median_max(bricks)},
      {"chunks_written", map.stats().chunks_written},
      {"chunks_unchanged", map.stats().chunks_unchanged},
      {"flush_s", flush_s},
      {"sync_s", sync_s},
      {"checkpoint_s", close_s},
      {"chunks", chunks},
      {"file_mb", static_cast<double>(fs::file_size(path)) / 1e6}};
  fs::remove(path);
  fs::remove(fs::path(path.string() + ".journal"));
  return result;
}

}  // namespace featsense::bench
