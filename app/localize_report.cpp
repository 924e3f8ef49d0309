#include "localize_report.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "featsense/bench/measurements.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;
using mapping::LocalizedScan;
using mapping::LocalizeStatus;

/// Events kept in the report, the first ones: a run that flips between states thousands of
/// times says so in its counts.
constexpr size_t kMaxEvents = 200;

double seconds_between(int64_t from_ns, int64_t to_ns) {
  return 1e-9 * static_cast<double>(to_ns - from_ns);
}

/// The value below which `share` of `values` lie (nearest rank); 0 for none.
double quantile(std::vector<double> values, double share) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t rank = static_cast<size_t>(share * static_cast<double>(values.size() - 1) + 0.5);
  return values[std::min(rank, values.size() - 1)];
}

nlohmann::json spread_json(const std::vector<double>& values, double scale) {
  if (values.empty()) return nullptr;
  double sum = 0.0;
  for (const double v : values) sum += v;
  return {{"mean", scale * sum / static_cast<double>(values.size())},
          {"median", scale * quantile(values, 0.5)},
          {"p95", scale * quantile(values, 0.95)},
          {"p99", scale * quantile(values, 0.99)},
          {"max", scale * quantile(values, 1.0)},
          {"count", values.size()}};
}

/// The stretches without a pose after the first fix: how long the sensor was lost each time.
nlohmann::json lost_periods_json(const std::vector<LocalizedScan>& scans, size_t first_fix,
                                 int64_t start_ns) {
  nlohmann::json periods = nlohmann::json::array();
  size_t i = first_fix;
  while (i < scans.size()) {
    if (scans[i].status != LocalizeStatus::kLost) {
      ++i;
      continue;
    }
    const size_t from = i;
    while (i < scans.size() && scans[i].status == LocalizeStatus::kLost) ++i;
    const int64_t end_ns = i < scans.size() ? scans[i].stamp_ns : scans.back().stamp_ns;
    periods.push_back({{"from_s", seconds_between(start_ns, scans[from].stamp_ns)},
                       {"seconds", seconds_between(scans[from].stamp_ns, end_ns)},
                       {"scans", i - from},
                       {"found_again", i < scans.size()}});
  }
  return periods;
}

/// Each posed scan's error against `truth` (the map's frame, no alignment), by status.
nlohmann::json truth_json(const std::vector<LocalizedScan>& scans, const slam::Trajectory& truth) {
  const slam::PoseInterpolator true_pose(truth);
  std::map<std::string, std::vector<double>> metres, degrees;
  size_t over_half_metre = 0;
  size_t without_truth = 0;
  for (const LocalizedScan& scan : scans) {
    if (!scan.T_map_sensor) continue;
    const std::optional<Eigen::Isometry3d> T = true_pose.at(scan.stamp_ns);
    if (!T) {
      ++without_truth;
      continue;
    }
    const std::string status = mapping::to_string(scan.status);
    const double m = (scan.T_map_sensor->translation() - T->translation()).norm();
    metres[status].push_back(m);
    degrees[status].push_back(
        slam::rotation_angle_deg(T->rotation().transpose() * scan.T_map_sensor->rotation()));
    if (scan.status == LocalizeStatus::kLocalized && m > 0.5) ++over_half_metre;
  }
  nlohmann::json out;
  for (const auto& [status, values] : metres) {
    out[status] = {{"translation_m", spread_json(values, 1.0)},
                   {"rotation_deg", spread_json(degrees[status], 1.0)}};
  }
  out["localized_over_0_5_m"] = over_half_metre;
  out["scans_without_truth"] = without_truth;
  return out;
}

}  // namespace

nlohmann::json localize_report_json(const config::Config& config, const LocalizeRun& run,
                                    const std::optional<slam::Trajectory>& truth) {
  const mapping::LocalizerCounts& c = run.counts;
  nlohmann::json report;
  report["map"] = run.map;
  report["input"] = {{"path", run.input.path},
                     {"format", run.input.format},
                     {"sensor", run.input.sensor.name},
                     {"rows", run.input.sensor.beams},
                     {"cols", run.input.sensor.columns}};
  report["frames"] = run.scans.size();
  report["frames_skipped"] = run.frames_skipped;
  report["warnings"] = run.warnings;
  report["interrupted"] = run.interrupted;
  report["wall_s"] = run.wall_s;
  const int64_t start_ns = run.scans.empty() ? 0 : run.scans.front().stamp_ns;
  const double recording_s =
      run.scans.empty() ? 0.0 : seconds_between(start_ns, run.scans.back().stamp_ns);
  report["recording_s"] = recording_s;
  report["real_time_factor"] = run.wall_s > 0.0 ? recording_s / run.wall_s : 0.0;
  report["peak_rss_mb"] = bench::peak_rss_mb();
  nlohmann::json rss = nlohmann::json::array();
  for (const auto& [seconds, mb] : run.rss_mb)
    rss.push_back({{"input_s", seconds}, {"rss_mb", mb}});
  report["rss_mb_over_input"] = rss;

  nlohmann::json& loc = report["localization"];
  loc["scans"] = {{"localized", 0}, {"odometry", 0}, {"lost", 0}};
  for (const auto& [status, count] : c.by_status) loc["scans"][status] = count;
  loc["localized"] = c.first_fix.has_value();
  if (c.first_fix) {
    const mapping::LocalizationFix& fix = *c.first_fix;
    loc["first_fix"] = {{"scan", fix.scan},
                        {"seconds_in", seconds_between(start_ns, fix.stamp_ns)},
                        {"found_by", fix.found_by},
                        {"descriptor_distance", fix.descriptor_distance},
                        {"fitness_m", fix.fitness_m},
                        {"inlier_fraction", fix.inlier_fraction},
                        {"position", {fix.position.x(), fix.position.y(), fix.position.z()}}};
    size_t after = 0, localized_after = 0;
    for (size_t i = fix.scan; i < run.scans.size(); ++i) {
      ++after;
      if (run.scans[i].status == LocalizeStatus::kLocalized) ++localized_after;
    }
    loc["localized_share_after_first_fix"] =
        after > 0 ? static_cast<double>(localized_after) / static_cast<double>(after) : 0.0;
    loc["lost_periods"] = lost_periods_json(run.scans, fix.scan, start_ns);
  }
  loc["fixes"] = c.fixes;
  loc["losses"] = c.losses;
  loc["unconfirmed_matches"] = c.unconfirmed_matches;
  loc["search"] = {{"keyframes", c.search_keyframes},
                   {"candidates", c.search_candidates},
                   {"verified", c.search_verified},
                   {"surface_refuted", c.unconfirmed_matches},
                   {"rejected", c.search_rejected},
                   {"layout_ms", c.layout_ms},
                   {"layout_search_ms", bench::timing_json(c.layout_search_ms)},
                   {"layout_bytes", c.layout_bytes},
                   {"keyframe_points_ms", c.keyframe_points_ms},
                   {"keyframe_points_bytes", c.keyframe_points_bytes}};
  nlohmann::json events = nlohmann::json::array();
  size_t event_count = 0;
  for (size_t i = 0; i < run.scans.size(); ++i) {
    if (run.scans[i].event.empty()) continue;
    if (++event_count > kMaxEvents) continue;
    events.push_back({{"scan", i},
                      {"t_s", seconds_between(start_ns, run.scans[i].stamp_ns)},
                      {"event", run.scans[i].event}});
  }
  loc["events"] = events;
  loc["event_count"] = event_count;

  std::vector<double> inliers, coverage, fitness;
  for (const LocalizedScan& scan : run.scans) {
    if (scan.status != LocalizeStatus::kLocalized || !scan.registered) continue;
    inliers.push_back(scan.inlier_fraction);
    coverage.push_back(scan.coverage);
    fitness.push_back(scan.fitness_m);
  }
  // Of the localized scans: the share of their points on the map's surface (where it
  // observed anything), the share where it did, and the RMS distance of those on it.
  report["fit"] = {{"inlier_fraction", spread_json(inliers, 1.0)},
                   {"coverage", spread_json(coverage, 1.0)},
                   {"fitness_mm", spread_json(fitness, 1000.0)}};
  std::vector<double> latency;
  for (const LocalizedScan& scan : run.scans) latency.push_back(scan.ms);
  double search_total_ms = 0.0;
  for (const double ms : c.search_ms) search_total_ms += ms;
  const size_t clouds = c.cloud_ms.size();
  report["timings"] = {
      {"tracking", bench::timing_json(c.tracking_ms)},
      {"tracking_parts",
       {{"odometry", bench::timing_json(c.odometry_ms)},
        {"cloud", bench::timing_json(c.cloud_ms)},
        {"register", bench::timing_json(c.register_ms)},
        {"points_per_scan",
         clouds > 0 ? static_cast<double>(c.points_per_scan_sum) / static_cast<double>(clouds)
                    : 0.0}}},
      {"search", bench::timing_json(c.search_ms)},
      {"search_total_s", 1e-3 * search_total_ms},
      {"per_scan", bench::timing_json(latency)}};
  report["map_cache"] = {{"map_chunks", c.map_chunks},
                         {"map_keyframes", c.map_keyframes},
                         {"chunks_read", c.chunks_made},
                         {"chunks_reused", c.chunks_reused},
                         {"chunks_evicted", c.chunks_evicted},
                         {"peak_cache_mb", static_cast<double>(c.peak_cache_bytes) / 1048576.0},
                         {"cache_limit_mb", config.localize.cache_mb},
                         {"chunk_read_ms", c.chunk_read_ms},
                         {"chunk_cells_ms", c.chunk_cells_ms},
                         {"targets_built", c.targets_built},
                         {"target_build_ms", c.target_build_ms},
                         {"targets_waited_for", c.targets_waited},
                         {"target_wait_ms", c.target_wait_ms}};
  if (truth) report["eval"] = truth_json(run.scans, *truth);
  return report;
}

}  // namespace featsense::app
