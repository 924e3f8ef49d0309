// APE, per-frame RPE and the KITTI segment metric on associated, aligned pose pairs.

#include "featsense/slam/trajectory/trajectory_metrics.hpp"

#include <algorithm>
#include <cmath>

namespace featsense::slam {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

/// E = (Q_a^-1 Q_b)^-1 (P_a^-1 P_b): how far the estimate's motion from a to b is from the
/// ground truth's.
Eigen::Isometry3d relative_error(const Trajectory& est, const Trajectory& gt, size_t a, size_t b) {
  const Eigen::Isometry3d gt_delta = gt.poses[a].inverse() * gt.poses[b];
  const Eigen::Isometry3d est_delta = est.poses[a].inverse() * est.poses[b];
  return gt_delta.inverse() * est_delta;
}

void require_paired(const Trajectory& est, const Trajectory& gt) {
  if (est.size() != gt.size()) {
    throw TrajectoryError("internal: metrics need index-paired trajectories of equal length");
  }
}

}  // namespace

double path_length_m(const Trajectory& trajectory) {
  double length = 0.0;
  for (size_t i = 1; i < trajectory.size(); ++i) {
    length += (trajectory.poses[i].translation() - trajectory.poses[i - 1].translation()).norm();
  }
  return length;
}

Alignment parse_alignment(const std::string& name) {
  if (name == "none") return Alignment::kNone;
  if (name == "se3") return Alignment::kSE3;
  if (name == "se3-scale") return Alignment::kSE3Scale;
  throw TrajectoryError("unknown alignment '" + name + "' (expected se3, se3-scale or none)");
}

std::string to_string(Alignment alignment) {
  switch (alignment) {
    case Alignment::kNone:
      return "none";
    case Alignment::kSE3:
      return "se3";
    case Alignment::kSE3Scale:
      return "se3-scale";
  }
  return "none";
}

double rotation_angle_rad(const Eigen::Matrix3d& R) {
  // The devkit's clamp keeps acos defined when rounding pushes the trace past 3.
  return std::acos(std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0));
}

double rotation_angle_deg(const Eigen::Matrix3d& R) {
  return rotation_angle_rad(R) * 180.0 / 3.14159265358979323846;
}

Trajectory apply_similarity(const Trajectory& trajectory, const Similarity& similarity) {
  Trajectory out = trajectory;
  for (Eigen::Isometry3d& T : out.poses) {
    const Eigen::Vector3d p = similarity.apply(T.translation());
    T.linear() = similarity.T.linear() * T.linear();
    T.translation() = p;
  }
  return out;
}

std::vector<double> absolute_position_errors(const Trajectory& estimate,
                                             const Trajectory& ground_truth) {
  require_paired(estimate, ground_truth);
  std::vector<double> errors(estimate.size());
  for (size_t i = 0; i < estimate.size(); ++i) {
    errors[i] = (ground_truth.poses[i].translation() - estimate.poses[i].translation()).norm();
  }
  return errors;
}

void relative_pose_errors(const Trajectory& estimate, const Trajectory& ground_truth,
                          std::vector<double>* translation_m, std::vector<double>* rotation_deg) {
  require_paired(estimate, ground_truth);
  translation_m->clear();
  rotation_deg->clear();
  for (size_t i = 0; i + 1 < estimate.size(); ++i) {
    const Eigen::Isometry3d E = relative_error(estimate, ground_truth, i, i + 1);
    translation_m->push_back(E.translation().norm());
    rotation_deg->push_back(rotation_angle_rad(E.linear()) * kRadToDeg);
  }
}

std::optional<KittiSegmentError> kitti_segment_error(const Trajectory& estimate,
                                                     const Trajectory& ground_truth) {
  require_paired(estimate, ground_truth);
  constexpr double kLengths[] = {100, 200, 300, 400, 500, 600, 700, 800};
  constexpr size_t kStep = 10;  // the devkit's step_size between segment starts, frames
  std::vector<double> distance(ground_truth.size(), 0.0);
  for (size_t i = 1; i < ground_truth.size(); ++i) {
    distance[i] =
        distance[i - 1] +
        (ground_truth.poses[i].translation() - ground_truth.poses[i - 1].translation()).norm();
  }
  double t_sum = 0.0;
  double r_sum = 0.0;
  size_t segments = 0;
  for (size_t first = 0; first < ground_truth.size(); first += kStep) {
    for (double length : kLengths) {
      const auto last_it = std::upper_bound(distance.begin() + static_cast<long>(first),
                                            distance.end(), distance[first] + length);
      if (last_it == distance.end()) continue;
      const size_t last = static_cast<size_t>(last_it - distance.begin());
      // The devkit inverts the other way round (P^-1 Q); the norm and angle are the same.
      const Eigen::Isometry3d E = relative_error(estimate, ground_truth, first, last);
      t_sum += E.translation().norm() / length;
      r_sum += rotation_angle_rad(E.linear()) / length;
      ++segments;
    }
  }
  if (segments == 0) return std::nullopt;
  KittiSegmentError result;
  result.segments = segments;
  result.t_err_pct = 100.0 * t_sum / static_cast<double>(segments);
  result.r_err_deg_per_m = kRadToDeg * r_sum / static_cast<double>(segments);
  return result;
}

TrajectoryEvaluation evaluate_trajectory(const Trajectory& estimate, const Trajectory& ground_truth,
                                         const TrajectoryEvaluationSettings& settings) {
  TrajectoryEvaluation result;
  result.association = associate(estimate, ground_truth, settings.association);
  Trajectory est;
  Trajectory gt;
  gt.has_stamps = ground_truth.has_stamps;
  for (size_t k = 0; k < result.association.size(); ++k) {
    const size_t i = result.association.estimate_index[k];
    const size_t j = result.association.ground_truth_index[k];
    est.push_back(ground_truth.stamps_ns[j], estimate.poses[i]);
    gt.push_back(ground_truth.stamps_ns[j], ground_truth.poses[j]);
  }
  if (settings.alignment != Alignment::kNone) {
    std::vector<Eigen::Vector3d> source;
    std::vector<Eigen::Vector3d> target;
    for (size_t k = 0; k < est.size(); ++k) {
      source.push_back(est.poses[k].translation());
      target.push_back(gt.poses[k].translation());
    }
    result.alignment = umeyama(source, target, settings.alignment == Alignment::kSE3Scale);
  }
  result.aligned_estimate = apply_similarity(est, result.alignment);
  result.ape_m = absolute_position_errors(result.aligned_estimate, gt);
  result.ape = error_statistics(result.ape_m);
  std::vector<double> rpe_t;
  std::vector<double> rpe_r;
  relative_pose_errors(result.aligned_estimate, gt, &rpe_t, &rpe_r);
  result.rpe_translation = error_statistics(rpe_t);
  result.rpe_rotation_deg = error_statistics(rpe_r);
  result.kitti = kitti_segment_error(result.aligned_estimate, gt);
  result.ground_truth_length_m = path_length_m(gt);
  return result;
}

}  // namespace featsense::slam
