#pragma once
/// The periodic map refinement (FeatSense's post-registration). Each time the odometry has
/// moved `distance_m`, the scans of that stretch are registered by voxelized GICP against scans
/// of the stretch before, already final. The guesses are the odometry's motion since the last
/// final scan applied to that scan's final pose, never the odometry's own poses, so the refined
/// poses do not inherit the odometry's drift. Drift grows with the distance travelled: the
/// stretch is registered as one correction that each scan takes in proportion to the distance
/// from the stretch's start (align_shared), so that the map stays continuous from stretch to
/// stretch and no one scan's error is handed on. A result that did not converge, moved the
/// guesses too far or fits the target worse than they do is dropped: the stretch keeps the
/// guesses, counted. Not thread-safe: one caller, scans in order.

#include <Eigen/Geometry>

#include <algorithm>
#include <cstddef>
#include <deque>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/refine/gaussian_cloud.hpp"
#include "featsense/slam/refine/vgicp.hpp"

namespace featsense::slam::refine {

/// A stretch's registration: voxels of the target twice the points' spacing, then equal to it
/// (finer ones would hold single points, with no surface to register to).
inline VgicpSettings stretch_vgicp(double voxel_m) {
  VgicpSettings settings;
  settings.voxel_sizes_m = {2.0 * voxel_m, voxel_m};
  settings.max_iterations = 32;
  settings.step_tolerance_m = 5e-4;
  settings.inlier_distance_m = 0.1;
  settings.fitness_voxel_m = std::max(0.5, 2.0 * voxel_m);
  settings.min_constraint_ratio = config::RefineConfig{}.min_constraint_ratio;
  return settings;
}

/// Where a setting has a config key (refine.*), its default is the configuration's
/// (config/include/featsense/config/config.hpp): one home per default.
struct RefineSettings {
  /// A stretch ends once the odometry has moved this far since the last final scan, metres.
  double distance_m = config::RefineConfig{}.distance_m;
  /// ... or once it holds this many scans (a sensor standing still): bounds the latency and
  /// the scans held.
  size_t max_scans = static_cast<size_t>(config::RefineConfig{}.max_scans);
  /// Each registered scan's points: one per voxel of this edge (refinement_cloud), metres,
  /// each with the covariance of this many nearest.
  double voxel_m = config::RefineConfig{}.voxel_m;
  int neighbours = 10;
  /// The target: this many scans of each stretch, evenly spaced along it, from the last
  /// target_stretches stretches (a longer memory drifts less from stretch to stretch).
  size_t target_scans = 4;
  size_t target_stretches = 3;
  /// A result that moves the guess by more than this is taken as diverged (metres, degrees).
  double max_correction_m = 0.5;
  double max_correction_deg = 3.0;
  /// A result fits worse than its guess when its inlier fraction is this much lower, or its
  /// fitness (RMS distance) this fraction higher.
  double inlier_tolerance = 0.01;
  double fitness_tolerance = 0.05;
  VgicpSettings vgicp = stretch_vgicp(config::RefineConfig{}.voxel_m);
};

/// refine.* of `config`.
RefineSettings from_config(const config::Config& config);

/// What became of a stretch's registration.
enum class RefineOutcome {
  first,          ///< the first scan: it fixes the frame, nothing to register it to
  refined,        ///< the registration's pose
  not_converged,  ///< kept the guess: the registration did not converge
  too_far,        ///< kept the guess: the result moved it beyond max_correction
  worse_fit,      ///< kept the guess: the result fits the target worse
  stood,          ///< not registered: the odometry held the pose through it (standing still)
};
const char* to_string(RefineOutcome outcome);

/// One registration: a stretch's scans against the stretch before.
struct StretchRegistration {
  size_t scans = 0;  ///< in the stretch
  RefineOutcome outcome = RefineOutcome::first;
  VgicpFit guess_fit;   ///< the guesses on the target's fitness voxels
  VgicpFit result_fit;  ///< the registration's result on them
  int iterations = 0;
  double step_m = 0.0;  ///< how far the result moved the stretch's last scan
  double step_deg = 0.0;
  /// Directions of the correction left at the odometry's motion as too weakly constrained.
  int weak_directions = 0;
  double ms = 0.0;  ///< the target's voxels and the registration
};

/// Totals over the run, for the report.
struct RefineCounts {
  size_t scans = 0;
  size_t refined = 0;  ///< stretches whose registration was taken
  size_t not_converged = 0;
  size_t too_far = 0;
  size_t worse_fit = 0;
  size_t stood = 0;  ///< stretches the sensor stood still through: nothing drifted to correct
  /// Refined stretches whose correction kept the odometry's motion along a weak direction.
  size_t weak_directions_held = 0;
  std::vector<StretchRegistration> stretches;
};

class SegmentRefiner {
 public:
  explicit SegmentRefiner(const RefineSettings& settings);

  /// Whether the next scan, at this odometry pose, needs its cloud: it ends the stretch, or it
  /// is one of the next target's scans. Clouds are what the refinement costs.
  bool needs_cloud(const Eigen::Isometry3d& T_odometry_sensor) const;

  /// Holds a scan: its odometry pose (map <- sensor) and, where needs_cloud() said so, its
  /// cloud in the sensor frame (refinement_cloud; else empty). True when the stretch is
  /// complete: call refine() before adding more.
  bool add(const Eigen::Isometry3d& T_odometry_sensor, GaussianCloud cloud);

  /// Registers the stretch held and gives the final pose of each of its scans, in the order
  /// added. Also ends the run with a partial stretch.
  std::vector<Eigen::Isometry3d> refine();

  size_t held() const { return held_.size(); }
  const RefineCounts& counts() const { return counts_; }

 private:
  struct HeldScan {
    Eigen::Isometry3d T_odometry_sensor;
    GaussianCloud cloud;
    double travelled_m = 0.0;  ///< since the anchor, along the odometry's path
  };
  double travelled_to(const Eigen::Isometry3d& T_odometry_sensor) const;
  /// The stretch's final poses: the registration's, or the guesses where it was dropped.
  std::vector<Eigen::Isometry3d> register_stretch(const std::vector<HeldScan>& stretch,
                                                  const std::vector<Eigen::Isometry3d>& guesses,
                                                  StretchRegistration& registration) const;
  void keep_as_target(const std::vector<HeldScan>& stretch,
                      const std::vector<Eigen::Isometry3d>& poses);

  RefineSettings settings_;
  std::vector<HeldScan> held_;
  double last_cloud_m_ = 0.0;  ///< travelled_m of the last held scan given a cloud
  /// The last final scan's odometry pose and final pose: the anchor of the next guesses.
  bool anchored_ = false;
  Eigen::Isometry3d anchor_odometry_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d anchor_final_ = Eigen::Isometry3d::Identity();
  /// The target scans of each of the last stretches, and all of them, in the map frame at
  /// their final poses.
  std::deque<GaussianCloud> recent_;
  GaussianCloud target_;
  RefineCounts counts_;
};

}  // namespace featsense::slam::refine
