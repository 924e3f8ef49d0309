// bench features: the feature extraction of every scan alone, per stage, and the features
// it finds.

#include <chrono>
#include <vector>

#include "featsense/bench/front_end_benchmarks.hpp"
#include "featsense/bench/measurements.hpp"
#include "featsense/slam/features/feature_extractor.hpp"

namespace featsense::bench {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

nlohmann::json bench_features(const config::Config& config, BenchScans& scans) {
  const slam::features::FeatureSettings settings = slam::features::from_config(config);

  std::vector<double> total, curvature, selection, intensity, edges, surfaces, edges_geometric;
  size_t confirmed = 0;
  bool warmed_up = false;
  while (const std::optional<slam::Scan> scan = scans.next()) {
    // The first scan warms up (the first allocations) and is extracted twice.
    if (!warmed_up) slam::features::extract_features(*scan, settings);
    warmed_up = true;
    slam::features::FeatureStats stats;
    const auto start = Clock::now();
    slam::features::extract_features(*scan, settings, &stats);
    total.push_back(ms_since(start));
    curvature.push_back(stats.curvature_ms);
    selection.push_back(stats.selection_ms);
    intensity.push_back(stats.intensity_ms);
    edges.push_back(static_cast<double>(stats.edges));
    edges_geometric.push_back(static_cast<double>(stats.edges_geometric));
    surfaces.push_back(static_cast<double>(stats.surfaces));
    if (stats.intensity_confirmed) ++confirmed;
  }
  scans.check_read();
  nlohmann::json result = scans.json("features");
  result["intensity_fusion"] = settings.intensity_fusion;
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

}  // namespace featsense::bench
