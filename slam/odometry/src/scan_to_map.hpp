#pragma once
/// One scan's features registered against the local feature map: correspondences (5 nearest
/// map points, a fitted line or plane), Ceres on SE(3) with a robust loss, outer loops that
/// re-deskew and re-associate, then the degeneracy and divergence checks.

#include <Eigen/Geometry>

#include "featsense/slam/odometry/local_feature_map.hpp"
#include "featsense/slam/odometry/odometry_result.hpp"
#include "featsense/slam/odometry/odometry_settings.hpp"
#include "featsense/slam/trajectory/sweep_motion.hpp"
#include "timed_features.hpp"

namespace featsense::slam::odometry {

/// Where the scan starts from and what it moved from.
struct RegistrationStart {
  Eigen::Isometry3d prediction;  ///< the initial guess, kept where the solve fails
  Eigen::Isometry3d previous;    ///< the previous scan's pose (map <- sensor)
  double elapsed_s = 0.0;        ///< since the previous scan; 0: no motion to deskew with
  GyroTwist twist;               ///< the gyroscope's bend of the sweep, where measured
  /// false: the features are registered rigidly, as measured (a sensor standing still: the
  /// motion within the sweep is the question, not a given).
  bool deskew = true;
};

/// Whether a pose moved less than `move_m` and turned less than what moves a point 10 m away
/// by as much: iterating further would change nothing that matters.
bool settled(const Eigen::Isometry3d& from, const Eigen::Isometry3d& to, double move_m);

/// The pose of the scan at its stamp. With settings.deskew (and elapsed_s > 0), `raw` is
/// moved to the stamp at every outer loop with the motion previous -> current estimate (and
/// start.twist).
/// Fills `result`'s diagnostics, reason, correspondences, degeneracy and timing. On too few
/// correspondences, a non-finite or diverging solve it returns start.prediction with
/// converged = false; along unobservable directions the pose keeps the prediction.
Eigen::Isometry3d register_to_map(const LocalFeatureMap& map, const TimedFeatures& raw,
                                  const RegistrationStart& start, const OdometrySettings& settings,
                                  OdometryResult& result);

}  // namespace featsense::slam::odometry
