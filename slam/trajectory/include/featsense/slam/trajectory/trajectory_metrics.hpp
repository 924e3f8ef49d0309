#pragma once
/// Errors of an estimated trajectory against ground truth, on associated pose pairs.
///
/// APE (absolute pose error, translation part, as evo_ape's default): per pair
/// ||t_gt - t_est_aligned|| in metres, after aligning the estimate to the ground truth.
/// RPE (relative pose error per frame, as evo_rpe --delta 1 --delta_unit f): for consecutive
/// pairs i, i+1, E = (Q_i^-1 Q_i+1)^-1 (P_i^-1 P_i+1) with Q ground truth and P the (aligned)
/// estimate; the translation error is ||t(E)|| (metres), the rotation error the angle of R(E)
/// (degrees).
/// KITTI segment metric (the KITTI odometry devkit): from every 10th pair, for each length
/// of 100, 200, ..., 800 m, the first pair whose ground-truth path length from the start
/// exceeds it closes a segment; E as above between the segment's ends; the translation error
/// is ||t(E)|| / length, the rotation error angle(R(E)) / length; both averaged over all
/// segments and reported in % and deg/m.

#include <optional>
#include <string>
#include <vector>

#include "featsense/slam/trajectory/association.hpp"
#include "featsense/slam/trajectory/error_statistics.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/slam/trajectory/umeyama.hpp"

namespace featsense::slam {

enum class Alignment { kNone, kSE3, kSE3Scale };

/// "none", "se3", "se3-scale"; throws TrajectoryError otherwise.
Alignment parse_alignment(const std::string& name);
std::string to_string(Alignment alignment);

struct KittiSegmentError {
  double t_err_pct = 0.0;        ///< mean translation error, % of segment length
  double r_err_deg_per_m = 0.0;  ///< mean rotation error, degrees per metre
  size_t segments = 0;
};

struct TrajectoryEvaluationSettings {
  AssociationSettings association;
  Alignment alignment = Alignment::kSE3;
};

struct TrajectoryEvaluation {
  Association association;
  Similarity alignment;                    ///< maps estimate positions into the ground truth's map
  Trajectory aligned_estimate;             ///< the associated estimate poses, aligned, gt stamps
  std::vector<double> ape_m;               ///< per pair
  ErrorStatistics ape;                     ///< metres
  ErrorStatistics rpe_translation;         ///< per frame, metres
  ErrorStatistics rpe_rotation_deg;        ///< per frame, degrees
  std::optional<KittiSegmentError> kitti;  ///< absent when the path is shorter than 100 m
  double ground_truth_length_m = 0.0;      ///< path length over the associated poses
};

/// The rotation angle of R, radians, in [0, pi].
double rotation_angle_rad(const Eigen::Matrix3d& R);
/// The same in degrees.
double rotation_angle_deg(const Eigen::Matrix3d& R);

/// Applies the similarity to every pose: p' = s R p + t, R' = R R_pose.
Trajectory apply_similarity(const Trajectory& trajectory, const Similarity& similarity);

/// APE per pose of two trajectories of equal length already paired index by index, metres.
std::vector<double> absolute_position_errors(const Trajectory& estimate,
                                             const Trajectory& ground_truth);

/// RPE over consecutive poses (index-paired, equal length): translation (m) and angle (deg).
void relative_pose_errors(const Trajectory& estimate, const Trajectory& ground_truth,
                          std::vector<double>* translation_m, std::vector<double>* rotation_deg);

/// The KITTI devkit's segment metric (index-paired, equal length); empty when no segment fits.
std::optional<KittiSegmentError> kitti_segment_error(const Trajectory& estimate,
                                                     const Trajectory& ground_truth);

/// Associates, aligns and computes every figure. Throws TrajectoryError (see associate(),
/// umeyama()).
TrajectoryEvaluation evaluate_trajectory(const Trajectory& estimate, const Trajectory& ground_truth,
                                         const TrajectoryEvaluationSettings& settings = {});

}  // namespace featsense::slam
