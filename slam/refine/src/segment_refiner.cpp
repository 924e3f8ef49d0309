#include "featsense/slam/refine/segment_refiner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::slam::refine {

const char* to_string(RefineOutcome outcome) {
  switch (outcome) {
    case RefineOutcome::first:
      return "first";
    case RefineOutcome::refined:
      return "refined";
    case RefineOutcome::not_converged:
      return "not converged";
    case RefineOutcome::too_far:
      return "moved too far";
    case RefineOutcome::worse_fit:
      return "fits worse";
    case RefineOutcome::stood:
      return "stood still";
  }
  return "?";
}

SegmentRefiner::SegmentRefiner(const RefineSettings& settings) : settings_(settings) {}

double SegmentRefiner::travelled_to(const Eigen::Isometry3d& T_odometry_sensor) const {
  if (held_.empty())
    return (T_odometry_sensor.translation() - anchor_odometry_.translation()).norm();
  return held_.back().travelled_m +
         (T_odometry_sensor.translation() - held_.back().T_odometry_sensor.translation()).norm();
}

bool SegmentRefiner::needs_cloud(const Eigen::Isometry3d& T_odometry_sensor) const {
  if (!anchored_) return true;
  const double travelled_m = travelled_to(T_odometry_sensor);
  const double spacing_m =
      settings_.distance_m / static_cast<double>(std::max<size_t>(settings_.target_scans, 1));
  return travelled_m >= settings_.distance_m || held_.size() + 1 >= settings_.max_scans ||
         travelled_m - last_cloud_m_ >= spacing_m;
}

bool SegmentRefiner::add(const Eigen::Isometry3d& T_odometry_sensor, GaussianCloud cloud) {
  const double travelled_m = anchored_ ? travelled_to(T_odometry_sensor) : 0.0;
  if (cloud.size() > 0) last_cloud_m_ = travelled_m;
  held_.push_back({T_odometry_sensor, std::move(cloud), travelled_m});
  // The first scan fixes the frame alone, at once.
  if (!anchored_) return true;
  return travelled_m >= settings_.distance_m || held_.size() >= settings_.max_scans;
}

std::vector<Eigen::Isometry3d> SegmentRefiner::register_stretch(
    const std::vector<HeldScan>& stretch, const std::vector<Eigen::Isometry3d>& guesses,
    StretchRegistration& registration) const {
  // In a frame at the stretch's start, so that the correction turns about it.
  const Eigen::Isometry3d to_local(Eigen::Translation3d(-anchor_final_.translation()));
  const VgicpTarget target(transformed(target_, to_local), settings_.vgicp);
  // Drift grows with the distance travelled: each scan's share of the correction.
  const double span_m = stretch.back().travelled_m;
  std::vector<double> shares;
  std::vector<SharedSource> sources;
  for (size_t i = 0; i < stretch.size(); ++i) {
    shares.push_back(span_m > 0.0
                         ? stretch[i].travelled_m / span_m
                         : static_cast<double>(i + 1) / static_cast<double>(stretch.size()));
    if (stretch[i].cloud.size() > 0) {
      sources.push_back({&stretch[i].cloud, to_local * guesses[i], shares.back()});
    }
  }
  const SharedVgicpResult result = align_shared(target, sources, settings_.vgicp);
  registration.iterations = result.iterations;
  registration.guess_fit = result.guess_fit;
  registration.result_fit = result.result_fit;
  registration.weak_directions = result.weak_directions;
  std::vector<Eigen::Isometry3d> poses;
  for (size_t i = 0; i < stretch.size(); ++i) {
    poses.push_back(to_local.inverse() *
                    apply_steps(to_local * guesses[i], result.steps, shares[i]));
  }
  // What the correction does at the stretch's end.
  registration.step_m = (poses.back().translation() - guesses.back().translation()).norm();
  registration.step_deg =
      rotation_angle_deg(poses.back().rotation() * guesses.back().rotation().transpose());
  if (!result.converged) {
    registration.outcome = RefineOutcome::not_converged;
  } else if (registration.step_m > settings_.max_correction_m ||
             registration.step_deg > settings_.max_correction_deg) {
    registration.outcome = RefineOutcome::too_far;
  } else if (registration.result_fit.inlier_fraction <
                 registration.guess_fit.inlier_fraction - settings_.inlier_tolerance ||
             registration.result_fit.fitness_m >
                 registration.guess_fit.fitness_m * (1.0 + settings_.fitness_tolerance)) {
    registration.outcome = RefineOutcome::worse_fit;
  } else {
    registration.outcome = RefineOutcome::refined;
    return poses;
  }
  return guesses;
}

std::vector<Eigen::Isometry3d> SegmentRefiner::refine() {
  std::vector<Eigen::Isometry3d> poses;
  if (held_.empty()) return poses;
  const auto start = std::chrono::steady_clock::now();
  std::vector<HeldScan> stretch = std::move(held_);
  held_.clear();
  last_cloud_m_ = 0.0;
  const bool anchored_before = anchored_;
  if (!anchored_) {
    // The first scan's pose is the odometry's: it defines the map frame.
    anchored_ = true;
    anchor_odometry_ = anchor_final_ = stretch.front().T_odometry_sensor;
  }
  const Eigen::Isometry3d odometry_to_final = anchor_final_ * anchor_odometry_.inverse();
  std::vector<Eigen::Isometry3d> guesses;
  for (const HeldScan& scan : stretch)
    guesses.push_back(odometry_to_final * scan.T_odometry_sensor);

  StretchRegistration registration;
  registration.scans = stretch.size();
  const bool clouds = std::any_of(stretch.begin(), stretch.end(),
                                  [](const HeldScan& scan) { return scan.cloud.size() > 0; });
  // A stretch the odometry held at the last final scan's pose throughout (the sensor stood
  // still) has not drifted: registering it again would only move a standing sensor by the
  // registration's noise.
  const bool stood =
      anchored_before && std::all_of(stretch.begin(), stretch.end(), [&](const HeldScan& scan) {
        return scan.T_odometry_sensor.matrix() == anchor_odometry_.matrix();
      });
  if (stood) {
    registration.outcome = RefineOutcome::stood;
    guesses.assign(stretch.size(), anchor_final_);  // exactly, not through a round trip
  }
  poses = clouds && target_.size() > 0 && !stood ? register_stretch(stretch, guesses, registration)
                                                 : guesses;
  anchor_odometry_ = stretch.back().T_odometry_sensor;
  anchor_final_ = poses.back();
  // A stood stretch saw nothing the target lacks: the stretches along the path stay it.
  if (!stood) keep_as_target(stretch, poses);

  counts_.scans += stretch.size();
  switch (registration.outcome) {
    case RefineOutcome::first:
      break;
    case RefineOutcome::refined:
      ++counts_.refined;
      if (registration.weak_directions > 0) ++counts_.weak_directions_held;
      break;
    case RefineOutcome::not_converged:
      ++counts_.not_converged;
      break;
    case RefineOutcome::too_far:
      ++counts_.too_far;
      break;
    case RefineOutcome::worse_fit:
      ++counts_.worse_fit;
      break;
    case RefineOutcome::stood:
      ++counts_.stood;
      break;
  }
  registration.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  counts_.stretches.push_back(registration);
  return poses;
}

void SegmentRefiner::keep_as_target(const std::vector<HeldScan>& stretch,
                                    const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<size_t> with_cloud;
  for (size_t i = 0; i < stretch.size(); ++i) {
    if (stretch[i].cloud.size() > 0) with_cloud.push_back(i);
  }
  // At most target_scans + 1 of the stretch (both its ends), evenly spaced.
  const size_t wanted = std::min(with_cloud.size(), settings_.target_scans + 1);
  if (wanted == 0) return;  // nothing new: the old target stays
  GaussianCloud kept;
  for (size_t k = 0; k < wanted; ++k) {
    const size_t i = with_cloud[with_cloud.size() - 1 - (k * with_cloud.size()) / wanted];
    const GaussianCloud moved = transformed(stretch[i].cloud, poses[i]);
    kept.points.insert(kept.points.end(), moved.points.begin(), moved.points.end());
    kept.covariances.insert(kept.covariances.end(), moved.covariances.begin(),
                            moved.covariances.end());
  }
  recent_.push_back(std::move(kept));
  while (recent_.size() > std::max<size_t>(settings_.target_stretches, 1)) recent_.pop_front();
  target_ = GaussianCloud{};
  for (const GaussianCloud& cloud : recent_) {
    target_.points.insert(target_.points.end(), cloud.points.begin(), cloud.points.end());
    target_.covariances.insert(target_.covariances.end(), cloud.covariances.begin(),
                               cloud.covariances.end());
  }
}

}  // namespace featsense::slam::refine
