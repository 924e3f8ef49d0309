#include "featsense/slam/odometry/feature_odometry.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

#include "featsense/slam/odometry/local_feature_map.hpp"
#include "featsense/slam/odometry/stand_detector.hpp"
#include "featsense/slam/trajectory/gyro_rotation.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"
#include "recent_fits.hpp"
#include "scan_to_map.hpp"
#include "timed_features.hpp"
#include "turn_search.hpp"

namespace featsense::slam::odometry {
namespace {

/// At most this many registrations of the second scan against the restarted map (see
/// restart_map): each removes about half of the first map's remaining distortion, and they
/// stop once the pose has settled.
constexpr int kMaxRestartRounds = 12;
/// The restart's rounds converge slowly: it stops on a finer change than a registration.
constexpr double kRestartSettledM = 2e-5;
/// A deskewed registration whose motion lies within this many times the stand's bound
/// (squared: 5 times the noise) is tried rigidly from the last pose for a stand.
constexpr double kStillSearch = 25.0;
/// A registration tells a standing sensor from a moving one only where it observes every
/// direction well: J^T J / N at least this along each (3 % of the rows facing it head-on).
/// Weaker directions are registered (odometry.degeneracy_threshold is lower), but their
/// noise bound is wide enough to take a walk along a corridor for a stand. With surfaces at
/// 0.2 m a 3 m end wall 20 m down a corridor gives 0.021 along it, and at 0.02 a creep at 8
/// cm/s towards it was held; parked sensors observe every direction beyond 0.03.
constexpr double kStandObservability = 0.03;

/// A fit within this is exact to every LiDAR's noise (real and simulated scans fit to 2-4 mm,
/// wrong minima to 7-20 mm): never searched again, however it compares with the last ones.
constexpr double kExactFitM = 1e-3;

bool observes_every_direction(const OdometryResult& r) {
  return r.diagnostics.converged && !r.diagnostics.degenerate &&
         r.information_eigenvalues.minCoeff() >= kStandObservability;
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

FeatureOdometry::FeatureOdometry(const OdometrySettings& settings)
    : settings_(settings),
      map_(new_map()),
      stand_(settings.stand_enter_scans, settings.stand_leave_scans),
      recent_fits_(std::make_unique<RecentFits>()) {}

FeatureOdometry::~FeatureOdometry() = default;

std::unique_ptr<LocalFeatureMap> FeatureOdometry::new_map() const {
  return std::make_unique<LocalFeatureMap>(settings_.edge_voxel_m, settings_.surface_voxel_m,
                                           settings_.map_radius_m);
}

OdometryResult FeatureOdometry::register_scan(const FeatureSet& features,
                                              const std::vector<ImuSample>& imu) {
  OdometryResult result;
  const TimedFeatures raw =
      voxel_filtered(features, settings_.edge_voxel_m, settings_.surface_voxel_m);
  result.scan_edges = raw.edges.size();
  result.scan_surfaces = raw.surfaces.size();

  // The constant-velocity prediction, scaled to the time since the last scan.
  RegistrationStart start{last_pose_, last_pose_, 0.0, GyroTwist()};
  if (started_) {
    result.elapsed_s = static_cast<double>(features.stamp_ns - last_stamp_ns_) * 1e-9;
    start.elapsed_s = std::max(result.elapsed_s, 0.0);
    start.twist = GyroTwist::from_samples(last_imu_, imu, last_stamp_ns_, features.stamp_ns,
                                          features.stamp_ns);
    if (result.elapsed_s > 0.0 && last_motion_s_ > 0.0) {
      start.prediction = last_pose_ * predicted_motion(features.stamp_ns, result.elapsed_s, imu);
    }
    if (!start.prediction.matrix().allFinite()) start.prediction = last_pose_;
    // Standing: the pose is held and the sweep rigid, until the registration says otherwise.
    if (stand_.standing()) start.deskew = false;
  }

  Eigen::Isometry3d pose = start.prediction;
  bool registered = false;
  if (raw.empty()) {
    result.diagnostics.converged = false;
    result.reason = "no features";
  } else if (map_->empty()) {
    result.reason = "first scan: the map starts here";
  } else {
    pose = register_to_map(*map_, raw, start, settings_, result);
    pose = search_if_poor(raw, start, pose, result);
    registered = true;
  }

  // Standing still: judged before the first map restarts (a sensor that stands needs no
  // deskewed first scan).
  // The verdict's pose is read only while standing: otherwise the pose is this registration's.
  StandDetector::Verdict verdict;
  if (registered && settings_.hold_still && result.elapsed_s > 0.0) {
    const StillTest still = still_test(raw, start, pose, result);
    verdict =
        stand_.update(last_pose_, last_precision_, still.pose, still.precision, still.converged);
  }
  if (!verdict.standing && first_scan_ && result.diagnostics.converged && start.elapsed_s > 0.0) {
    pose = restart_map(raw, start, pose, imu, result);
  }
  first_scan_.reset();
  if (!started_ && !raw.empty()) first_scan_ = std::make_unique<TimedFeatures>(raw);
  if (!started_ || result.elapsed_s > 0.0) {
    earlier_imu_ = std::move(last_imu_);
    last_imu_ = imu;
  }
  if (verdict.standing) {
    hold(verdict.pose, features.stamp_ns, result);
    return result;
  }
  if (verdict.resumed) {
    // The stand ended within the last leave_scans scans: the motion since the anchor is
    // spread over them, and the previous pose taken one such share back, for the prediction
    // and the deskewing.
    const Eigen::Isometry3d motion = motion_fraction(
        last_pose_.inverse() * pose, 1.0 / static_cast<double>(settings_.stand_leave_scans));
    last_pose_ = pose * motion.inverse();
  }
  last_precision_ = result.precision;
  add_to_map(raw, SweepMotion(last_pose_.inverse() * pose, result.elapsed_s, start.twist), pose,
             features.stamp_ns, result);
  return result;
}

Eigen::Isometry3d FeatureOdometry::predicted_motion(int64_t stamp_ns, double elapsed_s,
                                                    const std::vector<ImuSample>& imu) const {
  const double ratio = elapsed_s / last_motion_s_;
  const Eigen::Isometry3d constant_velocity = motion_fraction(last_motion_, ratio);
  // A standing sensor predicts no motion; the gyroscope's bias would only turn it.
  if (stand_.standing() || !settings_.gyro_prediction) return constant_velocity;
  const int64_t period_ns = static_cast<int64_t>(std::llround(last_motion_s_ * 1e9));
  const std::optional<Eigen::Matrix3d> turn_before =
      gyro_rotation(earlier_imu_, last_imu_, last_stamp_ns_ - period_ns, last_stamp_ns_);
  const std::optional<Eigen::Matrix3d> turn_now =
      gyro_rotation(last_imu_, imu, last_stamp_ns_, stamp_ns);
  if (!turn_before || !turn_now) return constant_velocity;
  return gyro_corrected_prediction(constant_velocity, last_motion_, *turn_before, *turn_now, ratio);
}

Eigen::Isometry3d FeatureOdometry::search_if_poor(const TimedFeatures& raw,
                                                  const RegistrationStart& start,
                                                  const Eigen::Isometry3d& pose,
                                                  OdometryResult& result) {
  Eigen::Isometry3d kept = pose;
  const double typical_m = recent_fits_->median();
  const double poor_m = std::max(settings_.poor_fit_ratio * typical_m, kExactFitM);
  const bool poor = result.diagnostics.converged
                        ? result.diagnostics.fitness_m > poor_m
                        : result.edge_correspondences + result.surface_correspondences > 0;
  if (settings_.turn_search_deg > 0.0 && typical_m > 0.0 && poor) {
    const auto found = register_from_turned_starts(*map_, raw, start, settings_, poor_m, result);
    if (found) kept = *found;
    result.turn_searched = true;
    result.turn_found = found.has_value();
  }
  if (result.diagnostics.converged) recent_fits_->add(result.diagnostics.fitness_m);
  return kept;
}

FeatureOdometry::StillTest FeatureOdometry::still_test(const TimedFeatures& raw,
                                                       const RegistrationStart& start,
                                                       const Eigen::Isometry3d& pose,
                                                       const OdometryResult& result) const {
  // A registration that observes a direction weakly or not at all (a corridor's axis) cannot
  // tell a standing sensor from one moving along it: it neither starts a stand nor ends one.
  StillTest test{pose, result.precision, observes_every_direction(result)};
  // Deskewing estimates the motion within the sweep from the scan itself: where the motion
  // is within a few times the noise it is mostly the noise, and the deskewed registration
  // scatters by more than its covariance says. Whether the sensor stands is asked of a rigid
  // registration from the last pose instead: the hypothesis under test, measured as it is.
  if (!start.deskew || !settings_.deskew) return test;  // rigid already (standing, or no deskew)
  int dimensions = 0;
  const double distance2 =
      mahalanobis_step(last_pose_, last_precision_, pose, result.precision, &dimensions);
  if (dimensions == 0 || distance2 > kStillSearch * chi_squared_999(dimensions)) return test;
  RegistrationStart rigid = start;
  rigid.prediction = last_pose_;
  rigid.deskew = false;
  OdometryResult rigid_result;
  const Eigen::Isometry3d rigid_pose = register_to_map(*map_, raw, rigid, settings_, rigid_result);
  if (observes_every_direction(rigid_result)) {
    test = StillTest{rigid_pose, rigid_result.precision, true};
  }
  return test;
}

void FeatureOdometry::hold(const Eigen::Isometry3d& pose, int64_t stamp_ns,
                           OdometryResult& result) {
  // Standing: the stand's pose, no motion to predict or deskew with, and the local map as it
  // was (a scan added at a scattered pose would move the map with it).
  result.standing = true;
  result.T_map_sensor = pose;
  result.T_previous_sensor = last_pose_.inverse() * pose;
  result.sweep = SweepMotion();
  result.reason = "standing still: the pose is held";
  last_pose_ = pose;
  last_motion_ = Eigen::Isometry3d::Identity();
  last_motion_s_ = result.elapsed_s;
  last_stamp_ns_ = stamp_ns;
  result.map_edges = map_->edge_count();
  result.map_surfaces = map_->surface_count();
}

Eigen::Isometry3d FeatureOdometry::restart_map(const TimedFeatures& raw,
                                               const RegistrationStart& start,
                                               const Eigen::Isometry3d& pose,
                                               const std::vector<ImuSample>& imu,
                                               OdometryResult& result) {
  // The first scan went into the map as measured: its motion was unknown. A sensor already
  // moving then (a car at 5 m/s moves 0.5 m within the sweep) leaves a distorted map that
  // every later scan would register to. Now that the motion is known, the map restarts from
  // the first scan deskewed with it, and this scan is registered again.
  Eigen::Isometry3d best = pose;
  if (!settings_.deskew) return best;
  // The first sweep's turn: the gyroscope's rate against its mean from the first stamp to
  // this one, the period of the motion it is deskewed with (last_imu_ is still the first's).
  const int64_t first_stamp_ns = last_stamp_ns_;
  const int64_t stamp_ns =
      first_stamp_ns + static_cast<int64_t>(std::llround(start.elapsed_s * 1e9));
  const GyroTwist first_twist =
      GyroTwist::from_samples(last_imu_, imu, first_stamp_ns, stamp_ns, first_stamp_ns);
  for (int round = 0; round < kMaxRestartRounds; ++round) {
    map_ = new_map();
    const TimedFeatures first = deskewed(
        *first_scan_, SweepMotion(start.previous.inverse() * best, start.elapsed_s, first_twist));
    map_->add(first.edges, first.surfaces, start.previous);
    OdometryResult again = result;
    const RegistrationStart from_best{best, start.previous, start.elapsed_s, start.twist};
    const Eigen::Isometry3d refined = register_to_map(*map_, raw, from_best, settings_, again);
    if (!again.diagnostics.converged) break;  // the restarted map holds the first scan anyway
    result = again;
    const bool done = settled(best, refined, kRestartSettledM);
    best = refined;
    if (done) break;
  }
  return best;
}

void FeatureOdometry::add_to_map(const TimedFeatures& raw, const SweepMotion& sweep,
                                 const Eigen::Isometry3d& pose, int64_t stamp_ns,
                                 OdometryResult& result) {
  const bool moved = started_ && result.elapsed_s > 0.0;
  const Eigen::Isometry3d& motion = sweep.motion();
  result.T_map_sensor = pose;
  result.T_previous_sensor = motion;
  if (moved) result.sweep = sweep;
  const auto map_start = std::chrono::steady_clock::now();
  if (!raw.empty()) {
    const TimedFeatures points = settings_.deskew && moved ? deskewed(raw, sweep) : raw;
    map_->add(points.edges, points.surfaces, pose);
  }
  result.timing.map_update_ms = ms_since(map_start);
  if (moved) {
    last_motion_ = motion;
    last_motion_s_ = result.elapsed_s;
  }
  if (!started_ || result.elapsed_s > 0.0) last_stamp_ns_ = stamp_ns;
  started_ = true;
  last_pose_ = pose;
  result.map_edges = map_->edge_count();
  result.map_surfaces = map_->surface_count();
}

}  // namespace featsense::slam::odometry
