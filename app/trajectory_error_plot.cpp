#include "trajectory_error_plot.hpp"

#include "featsense/viewer_export/time_series_plot.hpp"

namespace featsense::app {

TrajectoryErrorSeries trajectory_error_series(const slam::TrajectoryEvaluation& evaluation,
                                              const slam::Trajectory& truth, int64_t origin_ns) {
  TrajectoryErrorSeries series;
  series.timed = truth.has_stamps;
  const slam::Trajectory& aligned = evaluation.aligned_estimate;
  for (size_t k = 0; k < aligned.size(); ++k) {
    const Eigen::Isometry3d& T_true = truth.poses[evaluation.association.ground_truth_index[k]];
    series.time_s.push_back(series.timed
                                ? static_cast<double>(aligned.stamps_ns[k] - origin_ns) * 1e-9
                                : static_cast<double>(k));
    series.translation_m.push_back(evaluation.ape_m[k]);
    series.rotation_deg.push_back(
        slam::rotation_angle_deg(T_true.linear().transpose() * aligned.poses[k].linear()));
  }
  return series;
}

nlohmann::json write_trajectory_error_png(const std::filesystem::path& out,
                                          const TrajectoryErrorSeries& series,
                                          const nlohmann::json& loops_report) {
  viewer_export::TimeSeriesPlot plot;
  plot.title = "Trajectory error against the truth (aligned as the ATE)";
  plot.time_label = series.timed ? "time since the first scan (s)" : "pose";
  plot.times_s = series.time_s;
  plot.panels.push_back({"translation error (m)", series.translation_m, {215, 25, 28}});
  plot.panels.push_back({series.rotation_fixed
                             ? "rotation error (deg)"
                             : "rotation error (deg); the path is nearly straight: the alignment "
                               "leaves the turn about it free",
                         series.rotation_deg,
                         {35, 100, 220}});
  if (series.timed && loops_report.is_object() && loops_report.contains("loops")) {
    for (const nlohmann::json& loop : loops_report["loops"])
      if (loop.contains("time_s")) plot.marker_times_s.push_back(loop["time_s"].get<double>());
    plot.marker_label = "loop closed";
  }
  const std::string file = "trajectory_error.png";
  viewer_export::write_time_series_png(plot, (out / file).string());
  return {{"png", file}};
}

}  // namespace featsense::app
