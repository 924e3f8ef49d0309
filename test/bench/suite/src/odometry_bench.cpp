// bench odometry: the front end as `featsense map` runs it, poses only, one scan at a time:
// the product's odometry locator, and where asked the map pass's own refinement and loop
// stages (slam/mapping); per-stage times and the trajectory's error where it was simulated.

#include <algorithm>
#include <memory>
#include <optional>
#include <vector>

#include "featsense/bench/front_end_benchmarks.hpp"
#include "featsense/bench/measurements.hpp"
#include "featsense/mapping/loop_stage.hpp"
#include "featsense/mapping/map_pass.hpp"
#include "featsense/slam/odometry/odometry_locator.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "pose_stage_figures.hpp"

namespace featsense::bench {
namespace {

/// The odometry's own figures, from the product's locator: per-stage times of every scan
/// after the first two (which start the map), features per scan, degenerate and failed scans.
void add_odometry_figures(const slam::odometry::OdometryCounts& counts, nlohmann::json& result) {
  std::vector<double> features, registration, total, association, solve, map_update, found;
  double startup_ms = 0.0;
  for (size_t i = 0; i < counts.features_ms.size(); ++i) {
    // The first scan only starts the map, the second restarts it with the first deskewed once
    // the motion is known (FeatureOdometry): start-up, reported apart.
    if (i < 2) {
      startup_ms += counts.features_ms[i] + counts.registration_ms[i];
      continue;
    }
    features.push_back(counts.features_ms[i]);
    registration.push_back(counts.registration_ms[i]);
    total.push_back(counts.features_ms[i] + counts.registration_ms[i]);
    association.push_back(counts.association_ms[i]);
    solve.push_back(counts.solve_ms[i]);
    map_update.push_back(counts.map_update_ms[i]);
    found.push_back(counts.features_per_scan[i]);
  }
  result["timed_scans"] = total.size();
  result["startup_ms"] = startup_ms;
  result["features"] = timing_json(features);
  result["registration"] = timing_json(registration);
  result["total"] = timing_json(total);
  result["registration_stages_median_ms"] = {{"association", summarize_ms(association).median_ms},
                                             {"solve", summarize_ms(solve).median_ms},
                                             {"map_update", summarize_ms(map_update).median_ms}};
  result["features_per_scan"] = min_median_max(found);
  result["degenerate_scans"] = counts.degenerate_scans;
  result["failed_scans"] = counts.failed_scans;
  // The local feature map is bounded (odometry.map_radius): memory stays flat however long
  // the run.
  result["map_points"] = {{"edges", counts.map_edges}, {"surfaces", counts.map_surfaces}};
}

}  // namespace

/// The front end as `featsense map` runs it, poses only, one scan at a time: the product's
/// odometry locator, and with --refine / --loops the map pass's own refinement and loop
/// stages (slam/mapping). The scans are simulated outside the clock.
nlohmann::json bench_odometry(const config::Config& config, BenchScans& scans,
                              const OdometryBenchSettings& options) {
  const std::unique_ptr<slam::odometry::OdometryLocator> odometry =
      slam::odometry::make_odometry_locator(config);
  mapping::PassSettings stages = mapping::pass_settings(config);
  stages.integrate = false;
  if (options.refine) stages.refine = slam::refine::from_config(config);
  if (options.loops) stages.loops = slam::loops::from_config(config);
  mapping::MapPass pass(*odometry, stages, config, scans.sensor(), {}, {});
  slam::Trajectory estimate;  // the odometry's poses, before the refinement
  const auto map_final = [&pass](std::vector<mapping::PlacedScan> final) {
    for (mapping::PlacedScan& scan : final) {
      if (std::optional<mapping::LocatedScan> located = pass.make_rays(std::move(scan)))
        pass.integrate(std::move(*located));
    }
  };
  while (std::optional<slam::Scan> scan = scans.next()) {
    pass.count_read();
    std::optional<mapping::PlacedScan> placed = pass.locate(std::move(*scan));
    if (!placed) continue;
    estimate.push_back(placed->placement.stamp_ns, placed->placement.T_map_sensor);
    map_final(pass.refine(std::move(*placed)));
  }
  map_final(pass.finish_refinement());
  scans.check_read();
  const mapping::PassResult run = pass.close();

  nlohmann::json result = scans.json("odometry");
  result["intensity_fusion"] = config.odometry.intensity_fusion;
  result["optimization_steps"] = config.odometry.optimization_steps;
  result["deskew"] = config.odometry.deskew;
  add_odometry_figures(odometry->counts(), result);
  result["peak_rss_mb"] = peak_rss_mb();
  const std::optional<slam::Trajectory>& truth = scans.truth();
  if (!options.estimate_out.empty()) slam::write_tum(estimate, options.estimate_out);
  if (truth) add_trajectory_error(estimate, *truth, result);
  if (truth && !options.truth_out.empty()) slam::write_tum(*truth, options.truth_out);
  if (stages.refine) {
    if (!options.refined_out.empty()) slam::write_tum(run.poses, options.refined_out);
    nlohmann::json refine = bench_refine_json(run, *stages.refine);
    if (truth) add_trajectory_error(run.poses, *truth, refine);
    result["refine"] = refine;
  }
  if (run.loops) {
    mapping::LoopStage& stage = *pass.loop_stage();
    if (!options.corrected_out.empty())
      slam::write_tum(run.loops->corrected, options.corrected_out);
    nlohmann::json closed = bench_loops_json(*run.loops, stage.closer_after_finish(), truth);
    if (truth) add_trajectory_error(run.loops->corrected, *truth, closed);
    if (options.wrong_loop) {
      nlohmann::json wrong = inject_wrong_loop(stage.closer_after_finish(), truth);
      if (truth && !wrong.contains("skipped")) {
        add_trajectory_error(stage.corrected(), *truth, wrong);
        if (closed.contains("ape_rmse_m") && wrong.contains("ape_rmse_m"))
          wrong["ape_ratio"] = wrong["ape_rmse_m"].get<double>() /
                               std::max(closed["ape_rmse_m"].get<double>(), 1e-12);
      }
      closed["wrong_loop"] = wrong;
    }
    result["loops"] = closed;
  }
  return result;
}

}  // namespace featsense::bench
