#pragma once
// The front end's benchmarks: the feature extraction alone, and the odometry as `featsense
// map` runs it (with the map pass's refinement and loop stages where asked), one scan at a
// time, each returning its figures as the JSON `featsense bench` prints.

#include <nlohmann/json.hpp>

#include <string>

#include "featsense/bench/bench_scans.hpp"
#include "featsense/config/config.hpp"

namespace featsense::bench {

/// Times the feature extraction (features.*) of every scan: per-stage ms, features per scan.
nlohmann::json bench_features(const config::Config& config, BenchScans& scans);

struct OdometryBenchSettings {
  bool refine = false;      ///< the map refinement too (refine.*)
  bool loops = false;       ///< loop closure over the final poses (loop.*)
  bool wrong_loop = false;  ///< with loops: then a deliberately wrong loop, optimised
  /// Where to write the poses as TUM (empty: not written): the odometry's estimate, the
  /// refined poses, the loop-corrected ones, the simulated truth.
  std::string estimate_out;
  std::string refined_out;
  std::string corrected_out;
  std::string truth_out;
};

/// The product's odometry locator over every scan in order: per-stage ms, features per scan,
/// degenerate and failed scans, and the trajectory's error where the truth is known.
nlohmann::json bench_odometry(const config::Config& config, BenchScans& scans,
                              const OdometryBenchSettings& settings);

}  // namespace featsense::bench
