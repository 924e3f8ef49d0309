#include "eval_json.hpp"

#include <cstdio>

namespace featsense::app {
namespace {

nlohmann::json statistics_json(const slam::ErrorStatistics& s) {
  return {{"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"std", s.std},
          {"min", s.min},   {"max", s.max},   {"sse", s.sse},       {"count", s.count}};
}

std::string threshold_key(double threshold_m) {
  char key[32];
  std::snprintf(key, sizeof key, "%.2f", threshold_m);
  return key;
}

}  // namespace

nlohmann::json trajectory_evaluation_json(const slam::TrajectoryEvaluation& evaluation,
                                          const slam::TrajectoryEvaluationSettings& settings) {
  nlohmann::json rpe = statistics_json(evaluation.rpe_translation);
  rpe["rotation_deg"] = statistics_json(evaluation.rpe_rotation_deg);
  rpe["delta_frames"] = 1;
  const Eigen::Matrix3d R = evaluation.alignment.T.linear();
  const Eigen::Vector3d t = evaluation.alignment.T.translation();
  nlohmann::json json = {
      {"pairs", evaluation.association.size()},
      {"ape", statistics_json(evaluation.ape)},
      {"rpe", rpe},
      {"alignment",
       {{"method", slam::to_string(settings.alignment)},
        {"rotation",
         {{R(0, 0), R(0, 1), R(0, 2)}, {R(1, 0), R(1, 1), R(1, 2)}, {R(2, 0), R(2, 1), R(2, 2)}}},
        {"translation", {t.x(), t.y(), t.z()}},
        {"scale", evaluation.alignment.scale}}},
      {"association",
       {{"by_index", evaluation.association.by_index},
        {"max_diff_s", settings.association.max_diff_s},
        {"offset_s", settings.association.offset_s},
        {"max_stamp_diff_s", evaluation.association.max_stamp_diff_s}}},
      {"ground_truth_length_m", evaluation.ground_truth_length_m}};
  if (evaluation.kitti) {
    json["kitti"] = {{"t_err_pct", evaluation.kitti->t_err_pct},
                     {"r_err_deg_per_m", evaluation.kitti->r_err_deg_per_m},
                     {"segments", evaluation.kitti->segments}};
  }
  return json;
}

nlohmann::json mesh_comparison_json(const mesh::CompareResult& result,
                                    const mesh::CompareSettings& settings) {
  const mesh::DistanceStatistics& a = result.accuracy;
  nlohmann::json completeness = nlohmann::json::object();
  nlohmann::json precision = nlohmann::json::object();
  nlohmann::json fscore = nlohmann::json::object();
  for (const mesh::ThresholdScores& s : result.scores) {
    completeness[threshold_key(s.threshold_m)] = s.completeness;
    precision[threshold_key(s.threshold_m)] = s.precision;
    fscore[threshold_key(s.threshold_m)] = s.fscore;
  }
  return {{"points", result.points},
          {"accuracy",
           {{"mean_abs", a.mean_abs},
            {"mean_signed", a.mean_signed},
            {"std_signed", a.std_signed},
            {"std_abs", a.std_abs},
            {"rmse", a.rmse},
            {"median", a.median},
            {"p95", a.p95},
            {"max", a.max},
            {"count", a.count}}},
          {"completeness", completeness},
          {"precision", precision},
          {"fscore", fscore},
          {"signed", result.signed_distances},
          {"reference", result.reference_is_mesh ? "mesh" : "points"},
          {"reference_samples", result.reference_samples},
          {"samples_per_m2", result.samples_per_m2},
          {"max_dist_m", settings.max_dist_m},
          {"beyond_max_dist", result.beyond_max_dist},
          {"histogram",
           {{"of", "unsigned distance, m"},
            {"edges_m", result.histogram_edges_m},
            {"counts", result.histogram_counts}}}};
}

}  // namespace featsense::app
