#pragma once
// The map's benchmarks: integrating scans into the TSDF local map, moving a full local map
// through the HDF5 store, marching cubes over a stored map. Each returns its figures as the
// JSON `featsense bench` prints (median_ms, p95_ms, max_ms and what it counts).

#include <nlohmann/json.hpp>

#include <string>

#include "featsense/bench/prepared_scans.hpp"
#include "featsense/config/config.hpp"

namespace featsense::bench {

/// Integrates `scans` in order into a new local map (map.* of `config`, map.backend's
/// integrator), `passes` times; the first scan of each pass, which meets an empty map, is
/// reported apart.
nlohmann::json bench_tsdf(const config::Config& config, PreparedScans scans, int passes);

struct StoreBenchSettings {
  double shift_m = 10.0;  ///< distance of each move
  int scans = 4;          ///< outdoor scans integrated before the moves
  int repeat = 6;         ///< timed moves, out and back alternately
  std::string dir;        ///< folder of the store; empty: the temp folder
};

/// A local map filled with outdoor scans, moved back and forth through an HDF5 store: each
/// move spills the slab that leaves and loads the slab that enters.
nlohmann::json bench_store(const config::Config& config, const StoreBenchSettings& settings);

/// Marching cubes `repeat` times over the exact TSDF of a furnished hall of map.size
/// (synthetic_hall.hpp), with `threads` workers (0: all cores).
nlohmann::json bench_mesh(const config::MapConfig& map, int repeat, int threads);

}  // namespace featsense::bench
