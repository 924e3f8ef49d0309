// bench tsdf: realistic OS1-128 scans integrated into the local map, as a run does it: per-scan
// times, throughput and memory.

#include <spdlog/spdlog.h>

#include <chrono>
#include <memory>

#include "featsense/bench/map_benchmarks.hpp"
#include "featsense/bench/measurements.hpp"
#include "featsense/tsdf/integrator.hpp"

namespace featsense::bench {

nlohmann::json bench_tsdf(const config::Config& config, PreparedScans scans, int passes) {
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
  for (int pass = 0; pass < passes; ++pass) {
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
      {"passes", passes},
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

}  // namespace featsense::bench
