#include "pose_stage_figures.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <vector>

#include "featsense/bench/measurements.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::bench {

/// The trajectory's error against the truth, as JSON (nothing where it is undetermined).
void add_trajectory_error(const slam::Trajectory& estimate, const slam::Trajectory& truth,
                          nlohmann::json& out) {
  if (estimate.size() < 2) return;
  try {
    const slam::TrajectoryEvaluation e = slam::evaluate_trajectory(estimate, truth);
    out["ape_rmse_m"] = e.ape.rmse;
    out["rpe_translation_rmse_m"] = e.rpe_translation.rmse;
    out["path_length_m"] = e.ground_truth_length_m;
    if (e.kitti) out["kitti_translation_drift_percent"] = e.kitti->t_err_pct;
  } catch (const slam::TrajectoryError& e) {
    // A straight path leaves the alignment undetermined: no figures, and why.
    out["trajectory_evaluation_error"] = e.what();
  }
}

/// The refinement's figures: stretches, what was kept and why, its cost per scan and per
/// stretch against the time the stretch took to record, the corrections.
nlohmann::json bench_refine_json(const mapping::PassResult& run,
                                 const slam::refine::RefineSettings& settings) {
  const slam::refine::RefineCounts& counts = run.refine;
  // The first scan is a stretch of its own, with nothing to register.
  const double stretches = static_cast<double>(std::max<size_t>(
      counts.refined + counts.not_converged + counts.too_far + counts.worse_fit, 1));
  std::vector<double> stretch_ms, step_m, step_deg;
  double cloud_total_ms = 0.0, stretch_total_ms = 0.0;
  for (const double ms : run.refine_cloud_ms) cloud_total_ms += ms;
  for (const slam::refine::StretchRegistration& r : counts.stretches) {
    stretch_ms.push_back(r.ms);
    stretch_total_ms += r.ms;
    if (r.outcome != slam::refine::RefineOutcome::refined) continue;
    step_m.push_back(r.step_m);
    step_deg.push_back(r.step_deg);
  }
  const slam::Trajectory& refined = run.poses;
  const double recorded_ms =
      refined.size() < 2
          ? 0.0
          : static_cast<double>(refined.stamps_ns.back() - refined.stamps_ns.front()) * 1e-6;
  const double total_ms = cloud_total_ms + stretch_total_ms;
  return {{"distance_m", settings.distance_m},
          {"voxel_m", settings.voxel_m},
          {"stretches", counts.stretches.size()},
          {"scans", counts.scans},
          {"refined", counts.refined},
          {"kept_not_converged", counts.not_converged},
          {"kept_too_far", counts.too_far},
          {"kept_worse_fit", counts.worse_fit},
          {"clouds", run.refine_cloud_ms.size()},
          {"cloud", timing_json(run.refine_cloud_ms)},
          {"registration", timing_json(stretch_ms)},
          // What the refinement costs per scan: its clouds and registrations over the scans.
          {"per_scan_ms", total_ms / static_cast<double>(std::max<size_t>(counts.scans, 1))},
          // A stretch's refinement against the time its scans took to record: above 1 it keeps
          // up with the sensor.
          {"per_stretch_ms", total_ms / stretches},
          {"recorded_per_stretch_ms", recorded_ms / stretches},
          {"real_time_factor", recorded_ms / std::max(total_ms, 1e-9)},
          {"step_m", min_median_max(step_m)},
          {"step_deg", min_median_max(step_deg)}};
}

namespace {

std::optional<Eigen::Isometry3d> truth_at(const slam::Trajectory& truth, int64_t stamp_ns) {
  for (size_t i = 0; i < truth.size(); ++i) {
    if (truth.stamps_ns[i] == stamp_ns) return truth.poses[i];
  }
  return std::nullopt;
}

}  // namespace

/// The loop closure's figures: counts and times; with the truth, each loop's measured pose
/// against it: a loop more than 0.3 m or 2 degrees off is false (it would bend the map).
nlohmann::json bench_loops_json(const mapping::LoopOutcome& outcome,
                                const slam::loops::LoopCloser& closer,
                                const std::optional<slam::Trajectory>& truth) {
  const slam::loops::LoopCounts& counts = outcome.counts;
  nlohmann::json rejected = nlohmann::json::object();
  for (const auto& [reason, count] : counts.rejected) rejected[reason] = count;
  double total_ms = 0.0;
  for (const double ms : counts.keyframe_ms) total_ms += ms;
  for (const double ms : outcome.keyframe_cloud_ms) total_ms += ms;
  const slam::Trajectory& path = outcome.before;
  const double recorded_ms =
      path.size() < 2 ? 0.0
                      : static_cast<double>(path.stamps_ns.back() - path.stamps_ns.front()) * 1e-6;
  const slam::loops::GravityEstimate& gravity = outcome.gravity;
  nlohmann::json out = {{"keyframes", counts.keyframes},
                        {"candidates", counts.candidates},
                        {"verified", counts.verified},
                        {"accepted", outcome.loops.size()},
                        {"rejected", rejected},
                        {"keyframe_clouds_mb", static_cast<double>(counts.cloud_bytes) / 1e6},
                        {"cloud", timing_json(outcome.keyframe_cloud_ms)},
                        {"keyframe", timing_json(counts.keyframe_ms)},
                        {"optimise", timing_json(counts.optimise_ms)},
                        // The loop closure's time against the recording's: above 1 it keeps up
                        // with the sensor on one core.
                        {"real_time_factor", recorded_ms / std::max(total_ms, 1e-9)},
                        {"gravity_observations", gravity.observations}};
  if (gravity.observations > 0) {
    out["gravity_map_tilt_deg"] = {gravity.map_tilt_deg.x(), gravity.map_tilt_deg.y()};
    out["gravity_accel_bias_mps2"] = {gravity.accel_bias_mps2.x(), gravity.accel_bias_mps2.y(),
                                      gravity.accel_bias_mps2.z()};
    out["gravity_map_tilt_sigma_deg"] = gravity.tilt_sigma_deg;
    out["gravity_levelled_deg"] = gravity.levelled_deg;
    out["gravity_rms_whitened"] = gravity.rms_whitened;
  }
  if (!truth) return out;
  const std::vector<slam::loops::KeyframeRecord> keyframes = closer.keyframe_records();
  size_t false_loops = 0;
  double worst_m = 0.0, worst_deg = 0.0;
  for (const slam::loops::PoseGraphEdge& edge : closer.graph().edges()) {
    if (!edge.loop) continue;
    const std::optional<Eigen::Isometry3d> from = truth_at(*truth, keyframes[edge.from].stamp_ns);
    const std::optional<Eigen::Isometry3d> to = truth_at(*truth, keyframes[edge.to].stamp_ns);
    if (!from || !to) continue;
    const Eigen::Isometry3d error = (from->inverse() * *to).inverse() * edge.T_from_to;
    const double m = error.translation().norm();
    const double deg = slam::rotation_angle_deg(error.rotation());
    worst_m = std::max(worst_m, m);
    worst_deg = std::max(worst_deg, deg);
    if (m > 0.3 || deg > 2.0) ++false_loops;
  }
  out["false_loops"] = false_loops;
  out["worst_loop_error_m"] = worst_m;
  out["worst_loop_error_deg"] = worst_deg;
  return out;
}

/// A deliberately wrong loop added to the finished graph (and optimised): the keyframe three
/// quarters along the path claimed to lie 4 m ahead of the one a quarter along and turned 30
/// degrees, as confident as the first true loop. What the claim is off by against the truth,
/// and the weight the robust loss left it.
nlohmann::json inject_wrong_loop(slam::loops::LoopCloser& closer,
                                 const std::optional<slam::Trajectory>& truth) {
  const size_t n = closer.keyframes();
  if (n < 8) return {{"skipped", "fewer than 8 keyframes"}};
  const size_t from = n / 4, to = 3 * n / 4;
  Eigen::Isometry3d claim = Eigen::Isometry3d::Identity();
  claim.linear() =
      Eigen::AngleAxisd(30.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  claim.translation() = Eigen::Vector3d(4.0, 0.0, 0.0);
  slam::loops::Matrix6d information = slam::loops::Matrix6d::Identity();
  information.diagonal() << 1e4, 1e4, 1e4, 400.0, 400.0, 400.0;  // 0.01 rad, 5 cm
  for (const slam::loops::PoseGraphEdge& edge : closer.graph().edges()) {
    if (edge.loop) {
      information = edge.information;
      break;
    }
  }
  const std::vector<slam::loops::KeyframeRecord> keyframes = closer.keyframe_records();
  closer.add_loop_edge(from, to, claim, information);
  nlohmann::json out = {{"from", from}, {"to", to}, {"weight", closer.loops().back().weight}};
  const std::optional<Eigen::Isometry3d> a =
      truth ? truth_at(*truth, keyframes[from].stamp_ns) : std::nullopt;
  const std::optional<Eigen::Isometry3d> b =
      truth ? truth_at(*truth, keyframes[to].stamp_ns) : std::nullopt;
  if (a && b) {
    const Eigen::Isometry3d error = (a->inverse() * *b).inverse() * claim;
    out["claim_error_m"] = error.translation().norm();
    out["claim_error_deg"] = slam::rotation_angle_deg(error.rotation());
  }
  return out;
}

}  // namespace featsense::bench
