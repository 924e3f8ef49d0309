#pragma once
// trajectory_error.png of `featsense map` and `demo`: how far the estimated poses are from
// the true ones over time, after the same alignment as the ATE in report.json.

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <vector>

#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::app {

/// The error of each associated pose pair of an evaluation.
struct TrajectoryErrorSeries {
  std::vector<double> time_s;  ///< since `origin_ns`; the pair's index where times are unknown
  std::vector<double> translation_m;  ///< the APE of the pair (evaluation.ape_m)
  std::vector<double> rotation_deg;   ///< the angle between the aligned and the true rotation
  bool timed = true;                  ///< false: the truth has no stamps (KITTI without times)
  /// False where the path is (nearly) straight: a fit of positions leaves the turn about the
  /// line to chance, and the rotation error shows that turn as much as the estimate's error.
  bool rotation_fixed = true;
};

/// The series of `evaluation` (slam::evaluate_trajectory of an estimate against `truth`).
TrajectoryErrorSeries trajectory_error_series(const slam::TrajectoryEvaluation& evaluation,
                                              const slam::Trajectory& truth, int64_t origin_ns);

/// Writes `out`/trajectory_error.png: translation and rotation error over time, with the loops
/// closed (report.json's `loops.loops[].time_s`, seconds since the first scan, as `origin_ns`
/// should be) marked on the time axis. Returns the report's account: {"png": file name}.
nlohmann::json write_trajectory_error_png(const std::filesystem::path& out,
                                          const TrajectoryErrorSeries& series,
                                          const nlohmann::json& loops_report);

}  // namespace featsense::app
