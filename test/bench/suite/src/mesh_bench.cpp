// bench mesh: marching cubes over the exact TSDF of a furnished hall, the stored map of a
// large room: ms per run, voxels and triangles per second.

#include <tbb/task_arena.h>

#include <chrono>
#include <ctime>

#include "featsense/bench/map_benchmarks.hpp"
#include "featsense/bench/measurements.hpp"
#include "featsense/bench/synthetic_hall.hpp"
#include "featsense/mesh/marching_cubes.hpp"

namespace featsense::bench {

nlohmann::json bench_mesh(const config::MapConfig& map, int repeat, int threads) {
  const auto build_start = std::chrono::steady_clock::now();
  storage::MemoryChunkStore store =
      make_hall_map(Eigen::Vector3d(map.size_m[0], map.size_m[1], map.size_m[2]), map.voxel_size_m,
                    map.truncation_m);
  const double build_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - build_start).count();
  mesh::MeshingSettings settings;
  settings.threads = threads;

  mesh::MeshingStats stats;
  mesh::extract_mesh(store, settings, &stats);  // warm-up: first-touch page faults
  std::vector<double> times_ms;
  std::vector<double> cpu_ms;  // all threads: tells the cost apart from a busy machine's waits
  for (int i = 0; i < repeat; ++i) {
    const std::clock_t cpu_start = std::clock();
    mesh::extract_mesh(store, settings, &stats);
    cpu_ms.push_back(1e3 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC);
    times_ms.push_back(stats.seconds * 1e3);
  }
  const TimingSummary t = summarize_ms(times_ms);
  const double median_s = t.median_ms * 1e-3;
  const int workers = threads > 0 ? threads : tbb::this_task_arena::max_concurrency();
  return {
      {"benchmark", "mesh"},
      {"map", "synthetic furnished hall (exact TSDF, free space observed)"},
      {"map_size_m", map.size_m},
      {"voxel_size_m", map.voxel_size_m},
      {"truncation_m", map.truncation_m},
      {"map_build_s", build_s},
      {"threads", workers},
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

}  // namespace featsense::bench
