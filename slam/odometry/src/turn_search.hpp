#pragma once
/// A registration searched again from turned starts: where the prediction's turn is off by
/// more than the registration's basin (a turn that starts or stops within a period, without
/// a gyroscope), it converges to a wrong minimum that fits far worse than the scans before.

#include <Eigen/Geometry>

#include <optional>

#include "featsense/slam/odometry/local_feature_map.hpp"
#include "featsense/slam/odometry/odometry_result.hpp"
#include "featsense/slam/odometry/odometry_settings.hpp"
#include "scan_to_map.hpp"
#include "timed_features.hpp"

namespace featsense::slam::odometry {

/// The turns tried are multiples of this: a registration converged from 3 deg off the true
/// heading on the simulated scenes, and fell into a wrong minimum from 6-7 deg.
constexpr double kTurnSearchStepDeg = 3.0;

/// Registers `raw` again from start.prediction turned about the map frame's z axis (through
/// the predicted position) by +-kTurnSearchStepDeg, +-2 kTurnSearchStepDeg, ... up to
/// settings.turn_search_deg. `result` holds the registration from the prediction itself.
/// Returns the pose of the best that converged with about as many correspondences as it
/// and clearly fits better (at most `good_fit_m` where it did not converge), and sets
/// `result` to that registration; nothing where none does (`result` then only counts the
/// search's time).
std::optional<Eigen::Isometry3d> register_from_turned_starts(
    const LocalFeatureMap& map, const TimedFeatures& raw, const RegistrationStart& start,
    const OdometrySettings& settings, double good_fit_m, OdometryResult& result);

}  // namespace featsense::slam::odometry
