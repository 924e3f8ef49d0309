#include "featsense/slam/loops/loop_closer.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "featsense/slam/refine/voxel_gaussians.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::slam::loops {
namespace {

/// Neighbouring points' errors are not independent (one surface, one range bias): a fit is
/// taken to know the pose as well as this many independent points would.
constexpr double kEffectivePoints = 50.0;

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

const char* to_string(LoopRejection reason) {
  switch (reason) {
    case LoopRejection::not_converged:
      return "not converged";
    case LoopRejection::fitness:
      return "fitness";
    case LoopRejection::inliers:
      return "inliers";
    case LoopRejection::inconsistent:
      return "inconsistent with the odometry";
    case LoopRejection::ambiguous:
      return "ambiguous";
  }
  return "?";
}

std::optional<LoopRejection> fit_rejection(const refine::VgicpResult& result,
                                           const LoopSettings& settings) {
  if (!result.converged) return LoopRejection::not_converged;
  if (result.fitness_m > settings.max_fitness_m) return LoopRejection::fitness;
  if (result.inlier_fraction < settings.min_inlier_fraction) return LoopRejection::inliers;
  return std::nullopt;
}

LoopCloser::LoopCloser(const LoopSettings& settings) : settings_(settings) {}

KeyframeSelector::KeyframeSelector(double distance_m, double angle_deg)
    : distance_m_(distance_m), angle_deg_(angle_deg) {}

bool KeyframeSelector::next(const Eigen::Isometry3d& T_map_sensor) {
  if (!started_) {
    started_ = true;
    last_pose_ = keyframe_pose_ = T_map_sensor;
    return true;
  }
  travelled_m_ += (T_map_sensor.translation() - last_pose_.translation()).norm();
  last_pose_ = T_map_sensor;
  if (travelled_m_ - keyframe_travelled_m_ < distance_m_ &&
      rotation_angle_deg(keyframe_pose_.rotation().transpose() * T_map_sensor.rotation()) <
          angle_deg_)
    return false;
  keyframe_travelled_m_ = travelled_m_;
  keyframe_pose_ = T_map_sensor;
  return true;
}

LoopSettings from_config(const config::Config& config) {
  LoopSettings settings;
  settings.keyframe_distance_m = config.loop.keyframe_distance_m;
  settings.keyframe_angle_deg = config.loop.keyframe_angle_deg;
  settings.min_separation_s = config.loop.min_separation_s;
  settings.min_separation_m = config.loop.min_separation_m;
  settings.max_descriptor_distance = config.loop.max_descriptor_distance;
  settings.max_fitness_m = config.loop.max_fitness_m;
  settings.min_inlier_fraction = config.loop.min_inlier_fraction;
  settings.drift_per_m = config.loop.drift;
  settings.gravity.enabled = config.loop.gravity;
  settings.gravity.window_s = config.loop.gravity_window_s;
  settings.gyro.enabled = config.loop.gyro;
  return settings;
}

Matrix6d edge_information(const LoopSettings& settings, const Matrix6d& hessian, size_t points,
                          double fitness_m, double travelled_m) {
  Matrix6d covariance = Matrix6d::Zero();
  if (points >= 6 && hessian.allFinite()) {
    // The Hessian's shape (which directions the fit pins down), at the scale of the fit's
    // residuals: the best-known direction of translation gets fitness^2 / effective points.
    Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(hessian / static_cast<double>(points));
    Eigen::Matrix<double, 6, 1> values = eigen.eigenvalues();
    const double largest = std::max(values.maxCoeff(), 1e-12);
    values = values.cwiseMax(1e-6 * largest);
    const Matrix6d shape = eigen.eigenvectors() * values.cwiseInverse().asDiagonal() *
                           eigen.eigenvectors().transpose();
    const double best_translation =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(shape.bottomRightCorner<3, 3>())
            .eigenvalues()
            .minCoeff();
    const double sigma_m = std::max(fitness_m, settings.min_sigma_m);
    if (best_translation > 0.0)
      covariance = shape * (sigma_m * sigma_m / kEffectivePoints / best_translation);
  }
  const double sigma_rad = settings.min_sigma_rad + settings.odometry_sigma_rad_per_m * travelled_m;
  const double sigma_m = settings.min_sigma_m + settings.odometry_sigma_per_m * travelled_m;
  covariance.diagonal().head<3>().array() += sigma_rad * sigma_rad;
  covariance.diagonal().tail<3>().array() += sigma_m * sigma_m;
  Matrix6d out = covariance.inverse();
  return 0.5 * (out + out.transpose());
}

double LoopCloser::drift_radius_m(size_t query) const {
  return settings_.drift_base_m +
         settings_.drift_per_m * std::max(0.0, keyframes_[query].travelled_m - last_closure_m_);
}

double LoopCloser::drift_radius_deg(size_t query) const {
  return settings_.drift_base_deg +
         settings_.drift_deg_per_m * std::max(0.0, keyframes_[query].travelled_m - last_closure_m_);
}

refine::GaussianCloud LoopCloser::target_around(size_t keyframe) const {
  const size_t first =
      keyframe >= settings_.target_neighbours ? keyframe - settings_.target_neighbours : 0;
  const size_t last = std::min(keyframes_.size() - 1, keyframe + settings_.target_neighbours);
  const Eigen::Isometry3d T_keyframe_map = graph_.pose(keyframe).inverse();
  std::vector<Eigen::Vector3f> points;
  for (size_t j = first; j <= last; ++j) {
    const Eigen::Isometry3f T = (T_keyframe_map * graph_.pose(j)).cast<float>();
    for (const Eigen::Vector3f& p : keyframes_[j].cloud.points()) points.push_back(T * p);
  }
  return refine::with_covariances(points, settings_.neighbours);
}

std::vector<LoopCloser::Candidate> LoopCloser::find_candidates(size_t query) const {
  const Keyframe& q = keyframes_[query];
  const int64_t min_age_ns = static_cast<int64_t>(settings_.min_separation_s * 1e9);
  std::vector<size_t> eligible;
  for (size_t j = 0; j < query; ++j) {
    if (q.stamp_ns - keyframes_[j].stamp_ns >= min_age_ns &&
        q.travelled_m - keyframes_[j].travelled_m >= settings_.min_separation_m)
      eligible.push_back(j);
  }
  std::vector<Candidate> out;
  if (eligible.empty()) return out;

  // By descriptor: the nearest ring keys, then the full match with its yaw.
  std::vector<std::pair<double, size_t>> by_ring;
  for (size_t j : eligible)
    by_ring.emplace_back(ring_key_distance(q.descriptor, keyframes_[j].descriptor), j);
  const size_t keep = std::min(settings_.descriptor_candidates, by_ring.size());
  std::partial_sort(by_ring.begin(), by_ring.begin() + static_cast<std::ptrdiff_t>(keep),
                    by_ring.end());
  std::vector<Candidate> by_descriptor;
  for (size_t k = 0; k < keep; ++k) {
    const size_t j = by_ring[k].second;
    const ScanContextMatch m = match(q.descriptor, keyframes_[j].descriptor);
    if (m.distance > settings_.max_descriptor_distance) continue;
    by_descriptor.push_back({j,
                             descriptor_guess(keyframes_[j].T_front_end, q.T_front_end, m.yaw_rad),
                             "descriptor", m.distance});
  }
  std::sort(by_descriptor.begin(), by_descriptor.end(), [](const Candidate& a, const Candidate& b) {
    return a.descriptor_distance < b.descriptor_distance;
  });
  if (by_descriptor.size() > settings_.descriptor_verifications)
    by_descriptor.resize(settings_.descriptor_verifications);
  out = by_descriptor;

  // By position: the nearest keyframes within the drift radius, from the current poses.
  const Eigen::Isometry3d& T_query = graph_.pose(query);
  const double radius = drift_radius_m(query);
  std::vector<std::pair<double, size_t>> by_distance;
  for (size_t j : eligible) {
    const double d = (graph_.pose(j).translation() - T_query.translation()).norm();
    if (d <= radius) by_distance.emplace_back(d, j);
  }
  std::sort(by_distance.begin(), by_distance.end());
  size_t added = 0;
  for (const auto& [d, j] : by_distance) {
    if (added >= settings_.position_candidates) break;
    const bool known = std::any_of(out.begin(), out.end(), [&](const Candidate& c) {
      return std::abs(static_cast<long>(c.keyframe) - static_cast<long>(j)) <=
             static_cast<long>(settings_.target_neighbours);
    });
    if (known) continue;
    out.push_back({j, graph_.pose(j).inverse() * T_query, "position", 1.0});
    ++added;
  }
  return out;
}

void LoopCloser::add_odometry_edge(size_t keyframe, const refine::GaussianCloud& cloud) {
  PoseGraphEdge edge;
  edge.from = keyframe - 1;
  edge.to = keyframe;
  edge.T_from_to =
      keyframes_[keyframe - 1].T_front_end.inverse() * keyframes_[keyframe].T_front_end;
  const double travelled_m =
      keyframes_[keyframe].travelled_m - keyframes_[keyframe - 1].travelled_m;
  Matrix6d hessian = Matrix6d::Zero();
  size_t terms = 0;
  double fitness_m = settings_.min_sigma_m;
  if (previous_cloud_.size() > 0 && cloud.size() > 0) {
    const double voxel_m = settings_.vgicp.fitness_voxel_m;
    const refine::VoxelGaussians voxels(previous_cloud_, voxel_m);
    const refine::VgicpLinearization at = refine::linearize(voxels, cloud, edge.T_from_to);
    hessian = at.hessian;
    terms = at.terms;
    fitness_m =
        refine::measure_fit(voxels, cloud, edge.T_from_to, settings_.vgicp.inlier_distance_m)
            .fitness_m;
  }
  edge.information = edge_information(settings_, hessian, terms, fitness_m, travelled_m);
  graph_.add_edge(edge);
}

PoseGraphSummary LoopCloser::optimise_timed() {
  const auto start = std::chrono::steady_clock::now();
  PoseGraphSummary summary = graph_.optimize(settings_.graph);
  ++counts_.optimisations;
  counts_.optimise_ms.push_back(ms_since(start));
  size_t k = 0;
  for (LoopRecord& loop : loops_) {
    if (k < summary.loop_weights.size()) loop.weight = summary.loop_weights[k++];
  }
  return summary;
}

bool LoopCloser::add_keyframe(int64_t stamp_ns, double travelled_m,
                              const Eigen::Isometry3d& T_map_sensor,
                              const std::vector<Eigen::Vector3f>& points) {
  const auto start = std::chrono::steady_clock::now();
  Keyframe keyframe;
  keyframe.stamp_ns = stamp_ns;
  keyframe.travelled_m = travelled_m;
  keyframe.T_front_end = T_map_sensor;
  keyframe.descriptor = levelled_scan_context(T_map_sensor, points, settings_.scan_context);
  keyframe.cloud = CompactCloud(points);
  counts_.cloud_bytes += keyframe.cloud.bytes();
  const refine::GaussianCloud cloud =
      refine::with_covariances(keyframe.cloud.points(), settings_.neighbours);

  const size_t query = keyframes_.size();
  // A new node where the odometry's step from the last keyframe puts it, from that
  // keyframe's current (maybe corrected) pose.
  const Eigen::Isometry3d initial =
      query == 0
          ? T_map_sensor
          : graph_.pose(query - 1) * (keyframes_.back().T_front_end.inverse() * T_map_sensor);
  keyframes_.push_back(std::move(keyframe));
  graph_.add_node(initial);
  if (query > 0) add_odometry_edge(query, cloud);
  previous_cloud_ = cloud;
  ++counts_.keyframes;

  struct Verified {
    size_t candidate;
    refine::VgicpResult result;
    std::string found_by;
    double descriptor_distance;
    Eigen::Isometry3d T_map_query;  ///< where the loop puts the query
  };
  std::vector<Verified> verified;
  const bool resting = !loops_.empty() && travelled_m - last_closure_m_ < settings_.search_rest_m;
  const std::vector<Candidate> candidates =
      resting ? std::vector<Candidate>() : find_candidates(query);
  counts_.candidates += candidates.size();
  const auto reject = [&](LoopRejection reason) { ++counts_.rejected[to_string(reason)]; };
  for (const Candidate& candidate : candidates) {
    const refine::GaussianCloud target = target_around(candidate.keyframe);
    const refine::VgicpResult result =
        refine::align(target, cloud, candidate.guess, settings_.vgicp);
    if (const std::optional<LoopRejection> failed = fit_rejection(result, settings_)) {
      reject(*failed);
      continue;
    }
    ++counts_.verified;
    const Eigen::Isometry3d T_map_query = graph_.pose(candidate.keyframe) * result.T_target_source;
    const Eigen::Isometry3d& estimate = graph_.pose(query);
    if ((T_map_query.translation() - estimate.translation()).norm() > drift_radius_m(query) ||
        rotation_angle_deg(T_map_query.rotation().transpose() * estimate.rotation()) >
            drift_radius_deg(query)) {
      reject(LoopRejection::inconsistent);
      continue;
    }
    // The same place found twice (a descriptor and a position candidate) agrees with itself.
    verified.push_back({candidate.keyframe, result, candidate.found_by,
                        candidate.descriptor_distance, T_map_query});
  }
  bool accepted = false;
  if (!verified.empty()) {
    bool ambiguous = false;
    for (size_t a = 0; a < verified.size(); ++a) {
      for (size_t b = a + 1; b < verified.size(); ++b) {
        if ((verified[a].T_map_query.translation() - verified[b].T_map_query.translation()).norm() >
            settings_.ambiguity_m)
          ambiguous = true;
      }
    }
    if (ambiguous) {
      for (size_t k = 0; k < verified.size(); ++k) reject(LoopRejection::ambiguous);
    } else {
      const Verified& best = *std::min_element(verified.begin(), verified.end(),
                                               [](const Verified& a, const Verified& b) {
                                                 return a.result.fitness_m < b.result.fitness_m;
                                               });
      const Eigen::Isometry3d before = graph_.pose(query);
      PoseGraphEdge edge;
      edge.from = best.candidate;
      edge.to = query;
      edge.T_from_to = best.result.T_target_source;
      edge.information = edge_information(settings_, best.result.hessian, cloud.size(),
                                          best.result.fitness_m, 0.0);
      edge.loop = true;
      graph_.add_edge(edge);
      LoopRecord record;
      record.query = query;
      record.candidate = best.candidate;
      record.query_stamp_ns = stamp_ns;
      record.candidate_stamp_ns = keyframes_[best.candidate].stamp_ns;
      record.found_by = best.found_by;
      record.descriptor_distance = best.descriptor_distance;
      record.fitness_m = best.result.fitness_m;
      record.inlier_fraction = best.result.inlier_fraction;
      loops_.push_back(record);
      optimise_timed();
      const Eigen::Isometry3d& after = graph_.pose(query);
      loops_.back().correction_m = (after.translation() - before.translation()).norm();
      loops_.back().correction_deg =
          rotation_angle_deg(after.rotation() * before.rotation().transpose());
      last_closure_m_ = travelled_m;
      accepted = true;
    }
  }
  counts_.keyframe_ms.push_back(ms_since(start));
  return accepted;
}

void LoopCloser::add_loop_edge(size_t candidate, size_t query,
                               const Eigen::Isometry3d& T_candidate_query,
                               const Matrix6d& information) {
  PoseGraphEdge edge;
  edge.from = candidate;
  edge.to = query;
  edge.T_from_to = T_candidate_query;
  edge.information = information;
  edge.loop = true;
  graph_.add_edge(edge);
  LoopRecord record;
  record.query = query;
  record.candidate = candidate;
  record.query_stamp_ns = keyframes_.at(query).stamp_ns;
  record.candidate_stamp_ns = keyframes_.at(candidate).stamp_ns;
  record.found_by = "given";
  loops_.push_back(record);
  optimise_timed();
}

PoseGraphSummary LoopCloser::optimise() { return optimise_timed(); }

PoseGraphSummary LoopCloser::finish(const std::vector<int64_t>& path_stamps_ns,
                                    const std::vector<Eigen::Isometry3d>& path,
                                    const std::vector<ImuSample>& samples) {
  std::vector<int64_t> keyframe_stamps_ns;
  keyframe_stamps_ns.reserve(keyframes_.size());
  for (const Keyframe& keyframe : keyframes_) keyframe_stamps_ns.push_back(keyframe.stamp_ns);
  std::vector<GravityObservation> observations =
      gravity_observations(path_stamps_ns, path, samples, keyframe_stamps_ns, settings_.gravity);
  std::vector<Eigen::Matrix3d> R_map_node;
  R_map_node.reserve(graph_.size());
  for (const Eigen::Isometry3d& pose : graph_.poses()) R_map_node.push_back(pose.rotation());
  const GravityAgreement gravity_agreement =
      weigh_gravity_against_lidar(&observations, R_map_node, settings_.gravity.bias_prior_mps2);
  for (const GravityObservation& observation : observations)
    graph_.add_gravity(observation, settings_.gravity.bias_prior_mps2);
  std::vector<GyroObservation> turns =
      gyro_observations(samples, keyframe_stamps_ns, settings_.gyro);
  const TurnAgreement agreement = weigh_against_lidar(&turns, lidar_turns(&turns));
  if (!agreement.consistent) turns.clear();
  for (const GyroObservation& turn : turns) graph_.add_gyro(turn, settings_.gyro.bias_prior_radps);
  if (loops_.empty() && observations.empty() && turns.empty()) return {};
  PoseGraphSummary summary = optimise_timed();
  summary.turn_agreement = agreement;
  summary.gravity_agreement = gravity_agreement;
  return summary;
}

std::vector<LidarTurn> LoopCloser::lidar_turns(std::vector<GyroObservation>* turns) const {
  // The odometry edge between each pair of consecutive keyframes (edge k - 1 joins k - 1 and
  // k), its rotation and the sigma of its rotation's block. A turn without one (between two
  // sessions of a continued map) is dropped: nothing tells how the gyroscope compares there.
  std::vector<const PoseGraphEdge*> odometry_into(graph_.size(), nullptr);
  for (const PoseGraphEdge& edge : graph_.edges())
    if (!edge.loop && edge.to == edge.from + 1) odometry_into[edge.to] = &edge;
  std::vector<LidarTurn> out;
  std::vector<GyroObservation> kept;
  for (const GyroObservation& turn : *turns) {
    const PoseGraphEdge* odometry =
        turn.to < odometry_into.size() ? odometry_into[turn.to] : nullptr;
    if (odometry == nullptr || turn.from + 1 != turn.to) continue;
    LidarTurn lidar;
    lidar.rotation = odometry->T_from_to.rotation();
    const Matrix6d covariance = odometry->information.inverse();
    lidar.sigma_rad = covariance.diagonal().head<3>().cwiseMax(0.0).cwiseSqrt();
    out.push_back(lidar);
    kept.push_back(turn);
  }
  *turns = std::move(kept);
  return out;
}

TrajectoryCorrection LoopCloser::correction() const {
  TrajectoryCorrection out;
  for (size_t i = 0; i < keyframes_.size(); ++i)
    out.add_keyframe(keyframes_[i].travelled_m, keyframes_[i].T_front_end, graph_.pose(i));
  return out;
}

std::vector<KeyframeRecord> LoopCloser::keyframe_records() const {
  std::vector<KeyframeRecord> records;
  records.reserve(keyframes_.size());
  for (size_t i = 0; i < keyframes_.size(); ++i) {
    const Keyframe& keyframe = keyframes_[i];
    records.push_back({keyframe.stamp_ns, keyframe.travelled_m, graph_.pose(i), keyframe.descriptor,
                       keyframe.cloud});
  }
  return records;
}

std::vector<KeyframeRecord> LoopCloser::release_keyframe_records() {
  std::vector<KeyframeRecord> records;
  records.reserve(keyframes_.size());
  for (size_t i = 0; i < keyframes_.size(); ++i) {
    Keyframe& keyframe = keyframes_[i];
    records.push_back({keyframe.stamp_ns, keyframe.travelled_m, graph_.pose(i), keyframe.descriptor,
                       std::move(keyframe.cloud)});
    keyframe.cloud = CompactCloud();
  }
  return records;
}

}  // namespace featsense::slam::loops
