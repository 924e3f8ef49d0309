#pragma once
/// Tells a standing sensor from a moving one by the registration's own noise, and holds the
/// pose while it stands.
///
/// A sensor that stands still is registered again and again against the same place: each
/// registration scatters about the truth by its noise (a few millimetres to centimetres where
/// features are few and close), and every scan added to the local map at its scattered pose
/// moves the map with it, so the estimate wanders in a random walk. Here the motion of each
/// scan is compared with that noise (its Mahalanobis distance under the two poses'
/// covariances, from the registration's J^T J and residuals): motion within the noise for
/// `enter_scans` scans in a row is a stand. While it stands the pose is the stand's first
/// one, the local map takes no scans and the next scans are predicted there; a scan whose
/// registration leaves the noise about that pose for `leave_scans` scans in a row ends it,
/// and its registered pose (against the map as it was) is given. A single outlier (a scan
/// with few features, a person walking past) neither starts nor ends a stand. Not
/// thread-safe: one scan at a time, in order.

#include <Eigen/Geometry>

#include <cstddef>

#include "featsense/slam/odometry/pose_tangent.hpp"

namespace featsense::slam::odometry {

/// The squared Mahalanobis distance of the step from `from` to `to` in the registration's
/// tangent [rotation (rad, about the sensor, map frame), translation (m, map frame)], under
/// the sum of two covariances given as their inverses (the registrations' precision). Only
/// directions that both observe count (a direction neither pins down says nothing about
/// motion along it). A zero `from_precision` is the first scan's: exact as a pose, but its
/// points in the map as noisy as any scan's, so `to_precision` stands for it. Returns the
/// distance and, in `dimensions`, how many directions counted.
double mahalanobis_step(const Eigen::Isometry3d& from, const Matrix6d& from_precision,
                        const Eigen::Isometry3d& to, const Matrix6d& to_precision, int* dimensions);

/// The chi-squared quantile of probability 0.999 for 1 .. 6 degrees of freedom: a motion
/// within the noise exceeds it once in a thousand scans.
double chi_squared_999(int dimensions);

class StandDetector {
 public:
  /// enter_scans / leave_scans: scans in a row whose motion stays within / leaves the noise
  /// before a stand starts / ends (1 .. ).
  StandDetector(int enter_scans, int leave_scans);

  struct Verdict {
    bool standing = false;                                   ///< the pose given is the stand's
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< the pose to give
    bool resumed = false;  ///< this scan ended a stand: the registered pose, moving again
  };

  /// One registered scan: the last pose given and its precision, and this scan's registered
  /// pose and precision; `registered_ok`: the registration converged (one that did not says
  /// nothing about motion: a stand goes on holding, a moving sensor's run of still scans
  /// starts again).
  Verdict update(const Eigen::Isometry3d& previous, const Matrix6d& previous_precision,
                 const Eigen::Isometry3d& registered, const Matrix6d& precision,
                 bool registered_ok);

  bool standing() const { return standing_; }

 private:
  int enter_scans_;
  int leave_scans_;
  bool standing_ = false;
  int still_ = 0;  ///< scans in a row whose motion stayed within the noise
  int out_ = 0;    ///< standing: scans in a row registered beyond the noise of the anchor
  /// Where the run of still scans started: the stand's pose once it is one.
  Eigen::Isometry3d run_start_ = Eigen::Isometry3d::Identity();
  Matrix6d run_start_precision_ = Matrix6d::Zero();
  Eigen::Isometry3d anchor_ = Eigen::Isometry3d::Identity();
  Matrix6d anchor_precision_ = Matrix6d::Zero();
};

}  // namespace featsense::slam::odometry
