#include "featsense/mapping/localizer.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <list>
#include <memory>
#include <stdexcept>
#include <utility>

#include "featsense/config/config_error.hpp"
#include "featsense/mapping/saved_map.hpp"
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/loops/relocalizer.hpp"
#include "featsense/slam/odometry/odometry_locator.hpp"
#include "featsense/slam/refine/refinement_cloud.hpp"
#include "featsense/slam/trajectory/gyro_rotation.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"
#include "featsense/slam/trajectory/sweep_motion.hpp"
#include "keyframe_points.hpp"
#include "map_path.hpp"
#include "map_surface.hpp"
#include "map_targets.hpp"
#include "place_correlation.hpp"
#include "timed_scan_cloud.hpp"

namespace featsense::mapping {

const char* to_string(LocalizeStatus status) {
  switch (status) {
    case LocalizeStatus::kLost:
      return "lost";
    case LocalizeStatus::kLocalized:
      return "localized";
    case LocalizeStatus::kOdometry:
      return "odometry";
  }
  return "lost";
}

slam::refine::VgicpSettings LocalizerSettings::tracking_vgicp() {
  slam::refine::VgicpSettings settings;
  settings.voxel_sizes_m = {1.0, 0.5, 0.25};
  settings.max_iterations = 10;
  settings.step_tolerance_m = 5e-4;
  // A point of a thinned scan (one per half-metre voxel: a centroid, not a surface sample)
  // lies within a few centimetres of a plane, more on poles, trees and cars.
  settings.inlier_distance_m = 0.2;
  settings.fitness_voxel_m = 0.5;
  return settings;
}

LocalizerSettings localizer_from_config(const config::Config& config) {
  const config::LocalizeConfig& c = config.localize;
  LocalizerSettings s;
  s.radius_m = c.radius_m;
  s.cache_bytes = static_cast<size_t>(c.cache_mb * 1024.0 * 1024.0);
  s.voxel_m = c.voxel_m;
  s.max_points = static_cast<size_t>(c.max_points);
  s.min_inlier_fraction = c.min_inlier_fraction;
  s.max_fitness_m = c.max_fitness_m;
  s.contradiction_fraction = c.contradiction_fraction;
  s.contradictions = static_cast<size_t>(c.contradictions);
  s.odometry_timeout_s = c.odometry_timeout_s;
  return s;
}

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

std::string metres_text(double m) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f mm", 1000.0 * m);
  return text;
}

}  // namespace

/// Too few points to say anything: neither a fit nor a contradiction.
constexpr size_t kMinPoints = 30;
/// The map keyframes' points where the surface has none: one kept per voxel this wide (the
/// keyframes' own clouds are thinned to 0.4 m).
constexpr double kKeyframePointVoxel = 0.4;
/// The map's path, from where its surfaces were seen: one position kept per this distance.
constexpr double kPathSpacing = 2.0;

struct Localizer::State {
  State(const std::filesystem::path& map, const config::Config& config_in,
        const std::optional<Eigen::Isometry3d>& initial)
      : config(config_in),
        settings(localizer_from_config(config_in)),
        saved(read_saved_map(map)),
        path(saved, kPathSpacing),
        surface(map, settings.cache_bytes, settings.vgicp.voxel_sizes_m.back(),
                settings.vgicp.fitness_voxel_m, settings.min_weight),
        targets(surface, settings.radius_m, settings.vgicp, settings.vgicp.fitness_voxel_m, &path),
        initial_pose(initial) {
    relocalize = slam::loops::relocalize_from_config(config);
  }

  struct Pose {
    int64_t stamp_ns = 0;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  };
  /// The first of judge's tests a fit fails, in the order judge applies them.
  enum class Shortfall { kNone, kObserved, kCoverage, kHeld, kSurface, kInliers, kFitness };
  struct Fit {
    slam::refine::VgicpResult result;
    MapFit map;
    bool good = false;
    Shortfall shortfall = Shortfall::kObserved;  ///< not judged: nothing observed
    bool contradicts = false;
    size_t points = 0;
  };

  /// The search from scratch: the odometry from `T_first` (the belief, or the identity) and a
  /// relocalizer that tries the map keyframes around the belief too where there is one, and
  /// those alone where `belief_narrows` (the user's initial pose: a place elsewhere that looks
  /// alike is no match; a belief of the tracking's, after a loss, may be far off).
  void start_search(const std::optional<Eigen::Isometry3d>& belief, bool belief_narrows) {
    odometry = slam::odometry::make_odometry_locator(
        config, belief.value_or(Eigen::Isometry3d::Identity()));
    T_map_odometry = Eigen::Isometry3d::Identity();
    // The odometry's frame starts at the belief: the session lies where the belief says.
    search_settings = relocalize;
    search_settings.ring_candidates = settings.search_ring_candidates;
    search_settings.verifications = settings.search_verifications;
    if (belief) search_settings.guess = Eigen::Isometry3d::Identity();
    search_settings.guess_only = belief && belief_narrows;
    new_relocalizer();
    selector = std::make_unique<slam::loops::KeyframeSelector>(
        search_settings.loop.keyframe_distance_m, search_settings.loop.keyframe_angle_deg);
    last_search_keyframe_ns.reset();
    last.reset();
    before_last.reset();
  }

  /// A fresh relocalizer, the counts of the last one kept. Its candidates are checked against
  /// the map's surface: a map keyframe's cloud is one thinned scan from one lane, and a sensor
  /// a lane over, or driving the other way, sees too much of it otherwise to fit it.
  void new_relocalizer() {
    if (relocalizer) add_search_counts(relocalizer->counts(), counts);
    if (!layout && settings.search_layout_places > 0) {
      slam::loops::MapLayoutSettings layout_settings;
      layout_settings.peaks = settings.search_layout_places;
      const auto start = Clock::now();
      layout = std::make_shared<const slam::loops::MapLayout>(saved.keyframes, layout_settings);
      counts.layout_ms = ms_since(start);
      counts.layout_bytes = layout->counts().bytes;
    }
    relocalizer = std::make_unique<slam::loops::Relocalizer>(
        saved.keyframes, search_settings,
        [this](const Eigen::Isometry3d& guess, const slam::refine::GaussianCloud& cloud) {
          return check_place(guess, cloud);
        },
        layout);
  }

  /// The map keyframes' points for checking places beyond the surface, made the first time
  /// (none where the settings say so).
  const KeyframePoints* beyond_surface() {
    if (!settings.search_keyframe_points) return nullptr;
    if (!keyframe_points) {
      const auto start = Clock::now();
      keyframe_points =
          std::make_unique<const KeyframePoints>(saved.keyframes, kKeyframePointVoxel);
      counts.keyframe_points_ms = ms_since(start);
      counts.keyframe_points_bytes = keyframe_points->bytes();
    }
    return keyframe_points.get();
  }

  /// The surface around `position` for checking places (with the keyframes' points beyond
  /// it): kept for the next keyframes, which propose the same places.
  std::shared_ptr<const MapTarget> search_target(const Eigen::Vector3d& position) {
    const double cell_m = 0.25 * settings.search_radius_m;
    const std::array<int64_t, 2> key = {static_cast<int64_t>(std::floor(position.x() / cell_m)),
                                        static_cast<int64_t>(std::floor(position.y() / cell_m))};
    for (auto it = search_targets.begin(); it != search_targets.end(); ++it) {
      if (it->first != key) continue;
      std::shared_ptr<const MapTarget> target = it->second;
      search_targets.erase(it);
      search_targets.emplace_front(key, target);
      return target;
    }
    const Eigen::Vector3d centre((key[0] + 0.5) * cell_m, (key[1] + 0.5) * cell_m, position.z());
    std::shared_ptr<const MapTarget> target = build_map_target(
        surface, centre, settings.search_radius_m + cell_m, settings.search_voxel_sizes_m,
        settings.vgicp.fitness_voxel_m, settings.vgicp.fitness_voxel_m,
        settings.search_reach_m > 0.0 ? kUprightMaxNormalZ : -1.0, beyond_surface(), &path);
    search_targets.emplace_front(key, target);
    if (search_targets.size() > settings.search_targets_kept) search_targets.pop_back();
    return target;
  }

  /// A candidate place of a search keyframe: registered to the map's surface from `guess`
  /// and judged as a tracked scan is.
  slam::loops::PlaceCheck check_place(const Eigen::Isometry3d& guess,
                                      const slam::refine::GaussianCloud& cloud) {
    slam::loops::PlaceCheck check;
    if (cloud.size() < kMinPoints) {
      check.rejection = "too few points";
      return check;
    }
    const std::shared_ptr<const MapTarget> target = search_target(guess.translation());
    // Where near the proposed place the keyframe's walls fall on the map's, either way round
    // (a street or a corridor looks much the same both ways: the descriptor's heading may be
    // the map keyframe's where the sensor faces the other way).
    std::vector<Eigen::Isometry3d> starts;
    if (settings.search_reach_m > 0.0) {
      PlaceCorrelationSettings place;
      place.reach_m = settings.search_reach_m;
      place.max_normal_z = kUprightMaxNormalZ;
      for (const PlacePeak& peak :
           correlate_place(target->upright, target->observed_columns,
                           upright_points(cloud, guess.linear(), kUprightMaxNormalZ), guess, place))
        starts.push_back(peak.T_map_query);
    }
    if (starts.empty()) starts = {guess, guess * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ())};
    Fit fit;
    for (size_t i = 0; i < starts.size() && !found_firmly(fit); ++i) {
      Fit other = fit_on(*target, cloud, starts[i], false);
      if (i == 0 || found_firmly(other) || other.map.inliers > fit.map.inliers)
        fit = std::move(other);
    }
    check.fitness_m = fit.map.fitness_m;
    check.inlier_fraction = fit.map.inlier_fraction;
    check.coverage = fit.map.coverage;
    if (found_firmly(fit)) {
      check.T_map_query = fit.result.T_target_source;
    } else {
      check.rejection = fit.map.coverage < settings.min_coverage ? "surface: little of it mapped"
                        : fit.map.inlier_fraction < search_min_inlier_fraction()
                            ? "surface: inliers"
                        : fit.good ? "surface: upright surfaces"
                                   : "surface: fit";
    }
    return check;
  }

  double search_min_inlier_fraction() const {
    return std::min(1.0, settings.min_inlier_fraction + settings.search_extra_inliers);
  }
  /// A fit good enough to be found by: a tracked scan's, with more of it on the map, and
  /// its upright surfaces on the map's.
  bool found_firmly(const Fit& fit) const {
    return fit.good && fit.map.inlier_fraction >= search_min_inlier_fraction() && upright_fits(fit);
  }
  bool upright_fits(const Fit& fit) const {
    return fit.map.upright_observed >= settings.search_min_upright_points &&
           fit.map.upright_inlier_fraction >= settings.search_min_upright_inliers;
  }
  /// Why a fit that is good as a tracked scan's does not place the sensor from scratch.
  std::string upright_shortfall_text(const Fit& fit) const {
    char text[96];
    if (fit.map.upright_observed < settings.search_min_upright_points) {
      std::snprintf(text, sizeof text, "%zu points on upright surfaces the map observed",
                    fit.map.upright_observed);
    } else {
      std::snprintf(text, sizeof text, "%d %% of its upright surfaces on the map's",
                    static_cast<int>(100.0 * fit.map.upright_inlier_fraction));
    }
    return text;
  }

  static void add_search_counts(const slam::loops::RelocalizationCounts& from,
                                LocalizerCounts& to) {
    to.search_keyframes += from.keyframes;
    to.search_candidates += from.candidates;
    to.search_verified += from.verified;
    for (const auto& [reason, n] : from.rejected) to.search_rejected[reason] += n;
    to.layout_search_ms.insert(to.layout_search_ms.end(), from.layout_ms.begin(),
                               from.layout_ms.end());
  }

  /// `cloud` (deskewed, in the sensor's frame at the stamp) registered to `target` from
  /// `guess`, at each of its voxel sizes or at the finest alone, and judged.
  Fit fit_on(const MapTarget& target, const slam::refine::GaussianCloud& cloud,
             const Eigen::Isometry3d& guess, bool finest_only, size_t first_level = 0,
             double robust_scale = 0.0) const {
    Fit fit;
    fit.points = cloud.size();
    slam::refine::VgicpSettings vgicp = settings.vgicp;
    vgicp.robust_scale = robust_scale;
    fit.result =
        finest_only ? slam::refine::align_to_voxels(target.vgicp.levels.back(), cloud, guess, vgicp)
                    : slam::refine::align(target.vgicp, cloud, guess, vgicp, first_level);
    judge(target, cloud, fit);
    return fit;
  }

  /// How `fit.result` fits the map, and whether that is a fit, a contradiction, or neither.
  void judge(const MapTarget& target, const slam::refine::GaussianCloud& cloud, Fit& fit) const {
    fit.map =
        measure_map_fit(target, cloud, fit.result.T_target_source, settings.vgicp.inlier_distance_m,
                        settings.surface_angle_sigma_deg * M_PI / 180.0);
    // Where the map saw too little of what the scan sees, the fit says nothing either way.
    const bool telling = fit.map.observed >= settings.min_observed_points;
    const bool enough = telling && fit.map.coverage >= settings.min_coverage;
    // A pose the surface leaves free in some direction is no fit, however well it fits: it
    // may be sliding along a street. One held firmly is, converged or not: the iterations
    // that ran out were trading voxels by millimetres.
    const bool held = fit.map.position_sigma_m <= settings.max_position_sigma_m &&
                      fit.map.rotation_sigma_deg <= settings.max_rotation_sigma_deg;
    // Nor is one that rests on surfaces the map saw from afar: however many points hold it,
    // it is where those surfaces are, and they may be centimetres off. The map's share and
    // the scan's own (its points' spread) are independent: the pose is worth both together.
    const bool surfaces_sure = std::hypot(fit.map.surface_position_m, fit.map.position_sigma_m) <=
                               settings.max_surface_position_m;
    const bool inliers = fit.map.inlier_fraction >= settings.min_inlier_fraction;
    const bool close = fit.map.fitness_m <= settings.max_fitness_m;
    fit.good = enough && held && surfaces_sure && inliers && close;
    fit.shortfall = !telling         ? Shortfall::kObserved
                    : !enough        ? Shortfall::kCoverage
                    : !held          ? Shortfall::kHeld
                    : !surfaces_sure ? Shortfall::kSurface
                    : !inliers       ? Shortfall::kInliers
                    : !close         ? Shortfall::kFitness
                                     : Shortfall::kNone;
    fit.contradicts = telling && fit.map.inlier_fraction < settings.contradiction_fraction;
  }

  /// The fit's figures in a scan's answer.
  static void describe_fit(const Fit& fit, LocalizedScan& out) {
    out.fitness_m = fit.map.fitness_m;
    out.inlier_fraction = fit.map.inlier_fraction;
    out.coverage = fit.map.coverage;
    out.position_sigma_m = fit.map.position_sigma_m;
    out.rotation_sigma_deg = fit.map.rotation_sigma_deg;
    out.surface_position_m = fit.map.surface_position_m;
    out.surface_rotation_deg = fit.map.surface_rotation_deg;
    out.iterations = fit.result.iterations;
  }

  /// What keeps `fit` from being good (judge's first failed test), in words.
  static std::string shortfall_text(const Fit& fit) {
    char text[96];
    const MapFit& m = fit.map;
    switch (fit.shortfall) {
      case Shortfall::kObserved:
        std::snprintf(text, sizeof text, "%zu of its points where the map observed anything",
                      m.observed);
        break;
      case Shortfall::kCoverage:
        std::snprintf(text, sizeof text, "%d %% of the scan where the map observed anything",
                      static_cast<int>(100.0 * m.coverage));
        break;
      case Shortfall::kHeld:
        std::snprintf(text, sizeof text, "held to %.0f mm, %.2f deg only",
                      1000.0 * m.position_sigma_m, m.rotation_sigma_deg);
        break;
      case Shortfall::kSurface:
        std::snprintf(text, sizeof text, "its surfaces, seen from afar, may move it %.0f mm",
                      1000.0 * std::hypot(m.surface_position_m, m.position_sigma_m));
        break;
      case Shortfall::kInliers:
        std::snprintf(text, sizeof text, "%d %% of the scan on it",
                      static_cast<int>(100.0 * m.inlier_fraction));
        break;
      case Shortfall::kFitness:
      case Shortfall::kNone:
        std::snprintf(text, sizeof text, "fitness %.1f mm", 1000.0 * m.fitness_m);
        break;
    }
    return text;
  }

  void remember(int64_t stamp_ns, const Eigen::Isometry3d& T) {
    before_last = last;
    last = Pose{stamp_ns, T};
  }

  LocalizedScan search(const slam::Scan& scan) {
    LocalizedScan out;
    if (!odometry) start_search(initial_pose, true);
    std::string why;
    const std::optional<slam::ScanPlacement> placed = odometry->locate(scan, why);
    if (!placed || !next_search_keyframe(*placed, scan.stamp_ns)) return out;
    const std::vector<Eigen::Vector3f> points =
        slam::refine::voxel_centroids(scan, *placed, relocalize.loop.cloud_voxel_m);
    const std::optional<slam::loops::Relocalization> found = relocalizer->add_keyframe(
        scan.stamp_ns, placed->T_map_sensor, selector->travelled_m(), points);
    if (!found) return out;
    // The session's frame here is the odometry's, which starts at the belief.
    const Eigen::Isometry3d guess = found->T_map_session * placed->T_map_sensor;
    const slam::refine::GaussianCloud cloud =
        slam::refine::refinement_cloud(scan, *placed, settings.voxel_m, settings.neighbours);
    Fit fit;
    fit.points = cloud.size();
    fit.result.T_target_source = guess;
    if (cloud.size() >= kMinPoints)
      fit = fit_on(*targets.around(guess.translation()), cloud, guess, false);
    out.registered = true;
    describe_fit(fit, out);
    // The keyframes that placed it fitted firmly (check_place); this scan confirms the place
    // as a tracked scan would, with its upright surfaces on the map's.
    if (!fit.good || !upright_fits(fit)) {
      ++counts.unconfirmed_matches;
      const Eigen::Vector3d at = fit.result.T_target_source.translation();
      char text[240];
      std::snprintf(text, sizeof text,
                    "a match with the map's keyframes at (%.1f, %.1f, %.1f) that its surface "
                    "does not confirm (%s): searching on",
                    at.x(), at.y(), at.z(),
                    (fit.good ? upright_shortfall_text(fit) : shortfall_text(fit)).c_str());
      out.event = text;
      // The relocalizer keeps a placement once made; a fresh one searches on, with the same
      // odometry.
      new_relocalizer();
      return out;
    }
    const Eigen::Isometry3d T = fit.result.T_target_source;
    status = LocalizeStatus::kLocalized;
    T_map_odometry = T * placed->T_map_sensor.inverse();
    good_in_row = 1;
    contradicted_in_row = 0;
    on_odometry_since.reset();
    remember(scan.stamp_ns, T);
    out.status = status;
    out.T_map_sensor = T;
    ++counts.fixes;
    LocalizationFix fix;
    fix.scan = counts.scans;
    fix.stamp_ns = scan.stamp_ns;
    fix.found_by = found->found_by;
    fix.descriptor_distance = found->descriptor_distance;
    fix.fitness_m = fit.map.fitness_m;
    fix.inlier_fraction = fit.map.inlier_fraction;
    fix.position = T.translation();
    if (!counts.first_fix) counts.first_fix = fix;
    char text[240];
    std::snprintf(text, sizeof text,
                  "localized at (%.1f, %.1f, %.1f) by %s: %d %% of the scan on the map's "
                  "surface, fitness %s",
                  fix.position.x(), fix.position.y(), fix.position.z(), fix.found_by.c_str(),
                  static_cast<int>(100.0 * fix.inlier_fraction),
                  metres_text(fix.fitness_m).c_str());
    out.event = text;
    return out;
  }

  LocalizedScan lose(const slam::Scan& scan, const std::string& reason,
                     const Eigen::Isometry3d& belief) {
    LocalizedScan out;
    ++counts.losses[reason];
    out.event = "lost: " + reason;
    status = LocalizeStatus::kLost;
    on_odometry_since.reset();
    start_search(belief, false);
    // The scan that lost it is the first of the search.
    std::string why;
    const std::optional<slam::ScanPlacement> placed = odometry->locate(scan, why);
    if (placed) next_search_keyframe(*placed, scan.stamp_ns);
    return out;
  }

  /// Whether the search's scan at `placed` makes a keyframe: where the sensor has moved
  /// far enough from the last (the mapping's keyframe spacing), or where it has stood
  /// search_keyframe_interval_s since (a robot at rest at its dock is found without moving).
  bool next_search_keyframe(const slam::ScanPlacement& placed, int64_t stamp_ns) {
    const bool moved = selector->next(placed.T_map_sensor);
    const bool waited = last_search_keyframe_ns &&
                        1e-9 * static_cast<double>(stamp_ns - *last_search_keyframe_ns) >=
                            settings.search_keyframe_interval_s;
    if (!moved && !waited) return false;
    last_search_keyframe_ns = stamp_ns;
    return true;
  }

  LocalizedScan track(const slam::Scan& scan) {
    // The prediction: the odometry's motion while it runs, else constant velocity.
    Eigen::Isometry3d predicted = last->T;
    std::optional<Eigen::Isometry3d> odometry_pose;
    const auto odometry_start = Clock::now();
    if (odometry) {
      std::string why;
      const std::optional<slam::ScanPlacement> placed = odometry->locate(scan, why);
      if (placed) {
        odometry_pose = placed->T_map_sensor;
        predicted = T_map_odometry * placed->T_map_sensor;
      }
    }
    const double elapsed_s = 1e-9 * static_cast<double>(scan.stamp_ns - last->stamp_ns);
    if (!odometry_pose && before_last && elapsed_s > 0.0) {
      const double period_s = 1e-9 * static_cast<double>(last->stamp_ns - before_last->stamp_ns);
      if (period_s > 0.0) {
        // Constant velocity, its turn replaced by the gyroscope's where the scans carry it:
        // round a corner the turn rate changes faster than a repeated motion follows.
        const Eigen::Isometry3d last_motion = before_last->T.inverse() * last->T;
        const double ratio = elapsed_s / period_s;
        Eigen::Isometry3d motion = slam::motion_fraction(last_motion, ratio);
        const std::optional<Eigen::Matrix3d> turn_before =
            slam::gyro_rotation(earlier_imu, last_imu, before_last->stamp_ns, last->stamp_ns);
        const std::optional<Eigen::Matrix3d> turn_now =
            slam::gyro_rotation(last_imu, scan.imu, last->stamp_ns, scan.stamp_ns);
        if (turn_before && turn_now) {
          motion =
              slam::gyro_corrected_prediction(motion, last_motion, *turn_before, *turn_now, ratio);
        }
        predicted = last->T * motion;
      }
    }
    // The sweep's motion to a pose at the stamp: constant velocity from the last pose, bent by
    // the gyroscope's change of turn rate within the sweep where there is one.
    const slam::GyroTwist twist = slam::GyroTwist::from_samples(last_imu, scan.imu, last->stamp_ns,
                                                                scan.stamp_ns, scan.stamp_ns);
    const auto sweep_to = [&](const Eigen::Isometry3d& T) {
      return elapsed_s > 0.0 ? slam::SweepMotion(last->T.inverse() * T, elapsed_s, twist)
                             : slam::SweepMotion();
    };
    if (odometry) counts.odometry_ms.push_back(ms_since(odometry_start));
    const auto cloud_start = Clock::now();
    const TimedScanCloud cloud =
        timed_scan_cloud(scan, settings.voxel_m, settings.neighbours, settings.max_points);
    counts.cloud_ms.push_back(ms_since(cloud_start));
    counts.points_per_scan_sum += cloud.measured.size();
    const auto register_start = Clock::now();
    // Registered at every voxel size from the prediction, deskewed with the predicted motion;
    // then deskewed again with the motion that found, and registered again at the finest.
    Fit fit;
    if (cloud.measured.size() >= kMinPoints) {
      const std::shared_ptr<const MapTarget> target = targets.around(predicted.translation());
      // Tracked without a break, the prediction is good to centimetres: the coarsest voxels
      // add nothing to the finer ones.
      const bool steady = status == LocalizeStatus::kLocalized && good_in_row > 0;
      const size_t first_level = steady ? settings.steady_first_level : 0;
      // ... and what the map does not hold lets go of it (tracking_robust_scale); from a
      // prediction of the odometry's or a place just found, least squares: a kernel would let
      // a wrong place fit the part of the scan that matches it (a room turned by 90 deg).
      const double robust_scale = steady ? settings.tracking_robust_scale : 0.0;
      fit = fit_on(*target, deskewed(cloud, sweep_to(predicted)), predicted, false, first_level,
                   robust_scale);
      // Deskewed again with the motion found, and registered again from there; where that
      // fits worse than the first (it went astray), the first stands.
      const Eigen::Isometry3d found = fit.result.T_target_source;
      Fit again = fit_on(*target, deskewed(cloud, sweep_to(found)), found, true, 0, robust_scale);
      if (again.good || !fit.good) fit = std::move(again);
    } else {
      fit.result.T_target_source = predicted;
    }
    counts.register_ms.push_back(ms_since(register_start));
    LocalizedScan out;
    out.registered = fit.points > 0;
    describe_fit(fit, out);
    if (fit.good) {
      const Eigen::Isometry3d T = fit.result.T_target_source;
      if (status == LocalizeStatus::kOdometry) out.event = "localized again";
      status = LocalizeStatus::kLocalized;
      contradicted_in_row = 0;
      on_odometry_since.reset();
      if (odometry && odometry_pose) {
        T_map_odometry = T * odometry_pose->inverse();
        if (++good_in_row >= settings.settle_scans) odometry.reset();
      }
      remember(scan.stamp_ns, T);
      out.status = status;
      out.T_map_sensor = T;
      return out;
    }
    good_in_row = 0;
    contradicted_in_row = fit.contradicts ? contradicted_in_row + 1 : 0;
    if (contradicted_in_row >= settings.contradictions) {
      return lose(scan,
                  std::to_string(contradicted_in_row) +
                      " scans in a row with almost none of their points on the map",
                  predicted);
    }
    if (!on_odometry_since) on_odometry_since = scan.stamp_ns;
    if (1e-9 * static_cast<double>(scan.stamp_ns - *on_odometry_since) >
        settings.odometry_timeout_s) {
      return lose(scan, "no fit to the map for longer than localize.odometry_timeout", predicted);
    }
    if (status == LocalizeStatus::kLocalized) {
      out.event = "on odometry: " + shortfall_text(fit);
    }
    status = LocalizeStatus::kOdometry;
    if (!odometry) {
      // Started here: its first scan is this one, at the pose predicted for it.
      odometry = slam::odometry::make_odometry_locator(config, predicted);
      T_map_odometry = Eigen::Isometry3d::Identity();
      std::string why;
      odometry->locate(scan, why);
    }
    remember(scan.stamp_ns, predicted);
    out.status = status;
    out.T_map_sensor = predicted;
    return out;
  }

  config::Config config;
  LocalizerSettings settings;
  SavedMap saved;
  MapPath path;
  /// The map keyframes' points, for checking places where the surface has nothing: made at
  /// the first search.
  std::unique_ptr<const KeyframePoints> keyframe_points;
  MapSurface surface;
  MapTargets targets;
  std::optional<Eigen::Isometry3d> initial_pose;
  slam::loops::RelocalizeSettings relocalize;

  LocalizeStatus status = LocalizeStatus::kLost;
  std::unique_ptr<slam::odometry::OdometryLocator> odometry;
  Eigen::Isometry3d T_map_odometry = Eigen::Isometry3d::Identity();
  std::unique_ptr<slam::loops::Relocalizer> relocalizer;
  /// The map from above, made at the first search and kept for every search after it.
  std::shared_ptr<const slam::loops::MapLayout> layout;
  /// Targets of the places the search checked, the latest first.
  std::list<std::pair<std::array<int64_t, 2>, std::shared_ptr<const MapTarget>>> search_targets;
  std::unique_ptr<slam::loops::KeyframeSelector> selector;
  std::optional<int64_t> last_search_keyframe_ns;
  /// The current search's settings: relocalize.*, with the guess where it has a belief.
  slam::loops::RelocalizeSettings search_settings;
  std::optional<Pose> last;
  std::optional<Pose> before_last;
  /// The IMU's samples of the last two scans, for the gyroscope's turn.
  std::vector<slam::ImuSample> last_imu;
  std::vector<slam::ImuSample> earlier_imu;
  size_t good_in_row = 0;
  size_t contradicted_in_row = 0;
  std::optional<int64_t> on_odometry_since;
  LocalizerCounts counts;
};

namespace {

/// The checks a map must pass before anything is read from it besides its header.
void check_map_request(const std::filesystem::path& map) {
  if (map.extension() == ".vdb") {
    throw std::runtime_error(map.string() +
                             ": a .vdb keeps no keyframes to find the sensor by; localize in "
                             "the map.h5 it was exported from");
  }
  if (!std::filesystem::exists(map)) throw std::runtime_error("no such map: " + map.string());
}

}  // namespace

Localizer::Localizer(const std::filesystem::path& map, const config::Config& config,
                     const std::optional<Eigen::Isometry3d>& initial_pose) {
  check_map_request(map);
  state_ = std::make_unique<State>(map, config, initial_pose);
  const storage::MapMetadata& metadata = state_->surface.metadata();
  if (config.is_explicit("map.voxel_size") &&
      std::abs(config.map.voxel_size_m - metadata.voxel_size_m) > 1e-9) {
    throw config::ConfigError(
        map.string() + " has voxels of " + std::to_string(metadata.voxel_size_m) +
        " m, but map.voxel_size is set to " + std::to_string(config.map.voxel_size_m) + " m (" +
        config.explicit_keys.at("map.voxel_size") +
        "): a map is localized in at its own voxel size; leave map.voxel_size unset");
  }
  if (state_->saved.keyframes.empty()) {
    throw std::runtime_error(
        map.string() +
        " keeps no keyframes (it was made with given poses, with loop closure off or by an "
        "older featsense): the sensor is found in a map by its keyframes; map the place "
        "again without --gt");
  }
  if (state_->surface.chunks() == 0)
    throw std::runtime_error(map.string() + " holds no surface: its map is empty");
  state_->counts.map_keyframes = state_->saved.keyframes.size();
  state_->counts.map_chunks = state_->surface.chunks();
}

Localizer::~Localizer() = default;

LocalizedScan Localizer::add_scan(const slam::Scan& scan) {
  State& s = *state_;
  const auto start = Clock::now();
  const bool tracking = s.status != LocalizeStatus::kLost;
  LocalizedScan out = tracking ? s.track(scan) : s.search(scan);
  s.earlier_imu = std::move(s.last_imu);
  s.last_imu = scan.imu;
  out.sequence = scan.sequence;
  out.stamp_ns = scan.stamp_ns;
  out.ms = ms_since(start);
  ++s.counts.scans;
  ++s.counts.by_status[to_string(out.status)];
  (tracking ? s.counts.tracking_ms : s.counts.search_ms).push_back(out.ms);
  return out;
}

LocalizerCounts Localizer::counts() const {
  LocalizerCounts out = state_->counts;
  if (state_->relocalizer) State::add_search_counts(state_->relocalizer->counts(), out);
  const MapSurfaceCounts surface = state_->surface.counts();
  out.chunks_made = surface.chunks_made;
  out.chunks_reused = surface.chunks_reused;
  out.chunks_evicted = surface.chunks_evicted;
  out.peak_cache_bytes = surface.peak_cached_bytes;
  out.chunk_read_ms = surface.read_ms;
  out.chunk_cells_ms = surface.cells_ms;
  const MapTargetCounts targets = state_->targets.counts();
  out.targets_built = targets.built;
  out.targets_waited = targets.waited;
  out.target_build_ms = targets.build_ms;
  out.target_wait_ms = targets.wait_ms;
  return out;
}

const LocalizerSettings& Localizer::settings() const { return state_->settings; }

}  // namespace featsense::mapping
