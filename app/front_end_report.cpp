#include "front_end_report.hpp"

#include <vector>

#include "featsense/bench/measurements.hpp"

namespace featsense::app {
namespace {

constexpr double kDegrees = 180.0 / 3.14159265358979323846;

}  // namespace

using bench::summarize_ms;
using bench::timing_json;
using bench::TimingSummary;

std::string intensity_fusion_text(const slam::odometry::OdometryCounts& counts, bool enabled) {
  if (!enabled) return "off (odometry.intensity_fusion = false)";
  if (counts.intensity_confirmed_scans == 0) {
    return "off: the scans' intensity is missing or one value throughout";
  }
  if (counts.intensity_confirmed_scans < counts.scans) {
    return "on for " + std::to_string(counts.intensity_confirmed_scans) + " of " +
           std::to_string(counts.scans) +
           " scans (the others' intensity was missing or one value throughout)";
  }
  return "on";
}

nlohmann::json odometry_json(const slam::odometry::OdometryCounts& counts, bool fusion_enabled) {
  return {{"scans", counts.scans},
          {"degenerate_scans", counts.degenerate_scans},
          {"failed_scans", counts.failed_scans},
          {"turn_search", {{"searched", counts.turn_searches}, {"found", counts.turns_found}}},
          {"time_jumps", counts.time_jumps},
          {"standing",
           {{"stands", counts.stands},
            {"scans", counts.standing_scans},
            {"seconds", counts.standing_s}}},
          {"intensity_confirmed_scans", counts.intensity_confirmed_scans},
          {"intensity_fusion", intensity_fusion_text(counts, fusion_enabled)},
          {"features_per_scan",
           counts.scans ? counts.features_sum / static_cast<double>(counts.scans) : 0.0},
          {"timings",
           {{"features", timing_json(counts.features_ms)},
            {"registration", timing_json(counts.registration_ms)}}}};
}

nlohmann::json refine_json(const mapping::PassResult& run,
                           const slam::refine::RefineSettings& settings) {
  const slam::refine::RefineCounts& counts = run.refine;
  std::vector<double> registration_ms, step_m, step_deg;
  for (const slam::refine::StretchRegistration& stretch : counts.stretches) {
    if (stretch.outcome == slam::refine::RefineOutcome::first) continue;
    registration_ms.push_back(stretch.ms);
    if (stretch.outcome != slam::refine::RefineOutcome::refined) continue;
    step_m.push_back(stretch.step_m);
    step_deg.push_back(stretch.step_deg);
  }
  const TimingSummary steps_m = summarize_ms(step_m);
  const TimingSummary steps_deg = summarize_ms(step_deg);
  return {{"distance_m", settings.distance_m},
          {"voxel_m", settings.voxel_m},
          {"scans", counts.scans},
          {"registrations", registration_ms.size()},
          {"refined", counts.refined},
          {"kept_odometry",
           {{"not_converged", counts.not_converged},
            {"moved_too_far", counts.too_far},
            {"fits_worse", counts.worse_fit}}},
          // Stretches the sensor stood still through: not registered (nothing drifted).
          {"stood_still", counts.stood},
          // Refined stretches that kept the odometry's motion along a direction their points
          // hardly constrain (refine.min_constraint_ratio).
          {"weak_directions_held", counts.weak_directions_held},
          // How far the registrations moved the odometry's guess (its drift over a stretch).
          {"correction_m", {{"median", steps_m.median_ms}, {"max", steps_m.max_ms}}},
          {"correction_deg", {{"median", steps_deg.median_ms}, {"max", steps_deg.max_ms}}},
          {"most_scans_held", run.refine_most_held},
          {"timings",
           {{"cloud", timing_json(run.refine_cloud_ms)},
            {"registration", timing_json(registration_ms)}}}};
}

nlohmann::json loops_json(const mapping::LoopOutcome& outcome, double finish_ms) {
  const slam::loops::LoopCounts& counts = outcome.counts;
  nlohmann::json rejected = nlohmann::json::object();
  for (const auto& [reason, count] : counts.rejected) rejected[reason] = count;
  nlohmann::json list = nlohmann::json::array();
  const int64_t origin_ns = outcome.before.empty() ? 0 : outcome.before.stamps_ns.front();
  for (const slam::loops::LoopRecord& loop : outcome.loops) {
    list.push_back(
        {{"keyframe", loop.query},
         {"revisits_keyframe", loop.candidate},
         {"time_s", static_cast<double>(loop.query_stamp_ns - origin_ns) * 1e-9},
         {"revisits_time_s", static_cast<double>(loop.candidate_stamp_ns - origin_ns) * 1e-9},
         {"found_by", loop.found_by},
         {"descriptor_distance", loop.descriptor_distance},
         {"fitness_m", loop.fitness_m},
         {"inlier_fraction", loop.inlier_fraction},
         {"correction_m", loop.correction_m},
         {"correction_deg", loop.correction_deg},
         {"weight", loop.weight}});
  }
  const slam::loops::GravityEstimate& gravity = outcome.gravity;
  nlohmann::json gravity_json = {{"observations", gravity.observations}};
  if (gravity.observations > 0) {
    gravity_json["map_tilt_deg"] = {gravity.map_tilt_deg.x(), gravity.map_tilt_deg.y()};
    gravity_json["accel_bias_mps2"] = {gravity.accel_bias_mps2.x(), gravity.accel_bias_mps2.y(),
                                       gravity.accel_bias_mps2.z()};
    gravity_json["map_tilt_sigma_deg"] = gravity.tilt_sigma_deg;
    gravity_json["levelled_deg"] = gravity.levelled_deg;
    gravity_json["rms_whitened"] = gravity.rms_whitened;
  }
  const slam::loops::PoseGraphSummary& last = outcome.final_optimisation;
  if (last.gravity_agreement.observations > 0) {
    gravity_json["window_model_deg"] = last.gravity_agreement.model_rad * kDegrees;
    gravity_json["window_scatter_deg"] = last.gravity_agreement.scatter_rad * kDegrees;
  }
  nlohmann::json gyro_json = {{"edges", last.gyro_edges},
                              {"consistent_with_lidar", last.turn_agreement.consistent}};
  if (last.turn_agreement.edges > 0) {
    const auto triple = [](const Eigen::Vector3d& v) {
      return nlohmann::json::array({v.x(), v.y(), v.z()});
    };
    gyro_json["bias_radps"] = triple(last.gyro_bias_radps);
    gyro_json["disagreement_deg"] = triple(last.turn_agreement.disagreement_rad * kDegrees);
    gyro_json["lidar_sigma_deg"] = triple(last.turn_agreement.lidar_sigma_rad * kDegrees);
  }
  return {{"keyframes", counts.keyframes},
          {"candidates", counts.candidates},
          {"verified", counts.verified},
          {"accepted", outcome.loops.size()},
          {"rejected", rejected},
          {"optimisations", counts.optimisations},
          {"max_scan_correction_m", outcome.corrections_max_m},
          {"keyframe_clouds_mb", static_cast<double>(counts.cloud_bytes) / 1e6},
          {"loops", list},
          {"gravity", gravity_json},
          {"gyro", gyro_json},
          {"timings",
           {{"keyframe", timing_json(counts.keyframe_ms)},
            {"optimise", timing_json(counts.optimise_ms)},
            {"pipeline_wait_ms", outcome.keyframe_queue_wait_ms},
            {"after_last_scan_ms", finish_ms}}}};
}

}  // namespace featsense::app
