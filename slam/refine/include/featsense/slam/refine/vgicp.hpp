#pragma once
/// Voxelized GICP (Koide, Yokozuka, Oishi, Banno 2021): a source cloud with covariances
/// registered to the voxel Gaussians of a target, minimising the distribution-to-distribution
/// cost sum (mu_v - T p)^T (C_v + R C_p R^T)^-1 (mu_v - T p) over each point and the voxel it
/// falls in, by Levenberg-Marquardt on SE(3), the sums over the points in parallel (TBB), from
/// coarse voxels to fine ones.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "featsense/slam/refine/gaussian_cloud.hpp"
#include "featsense/slam/refine/voxel_gaussians.hpp"

#include <vector>

namespace featsense::slam::refine {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

struct VgicpSettings {
  /// Coarse to fine: a voxel catches a guess up to about half its size off, the finer ones
  /// give the accuracy (a voxel's mean lies on the surface only where the voxel holds one
  /// surface).
  std::vector<double> voxel_sizes_m = {1.0, 0.5, 0.25};
  int max_iterations = 64;  ///< per voxel size
  /// Converged when a step moves the pose less than this (and turns it less than this over
  /// 10 m).
  double step_tolerance_m = 5e-4;
  /// A source point is an inlier when it falls in a voxel of the target and lies within this
  /// of the voxel's surface (along its normal), metres: for the inlier fraction and fitness.
  double inlier_distance_m = 0.1;
  /// The voxel size the fitness is measured with (align() only): coarse enough that a
  /// sampled surface fills its voxels, fine enough that a voxel mostly holds one surface.
  double fitness_voxel_m = 0.5;
  /// align_shared only: a direction of the correction constrained less than this fraction as
  /// firmly as the best-constrained one keeps the guesses (weak_directions.hpp); 0 corrects
  /// every direction.
  double min_constraint_ratio = 0.0;
  /// Geman-McClure's scale on each term's Mahalanobis distance: a term at distance d weighs
  /// (k^2 / (k^2 + d^2))^2, so that points on what the target does not hold (a car moved
  /// since the map was made) stop pulling; 0: every term counts in full (least squares). The
  /// result's Hessian, and align_shared's weak directions, are least squares' either way.
  double robust_scale = 0.0;
};

/// What a registration found, and how well: for the fitness check of the refinement and the
/// information matrices of loop edges.
struct VgicpResult {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  bool converged = false;
  int iterations = 0;
  double fitness_m = 0.0;        ///< RMS distance of the inliers to their voxel's surface
  double inlier_fraction = 0.0;  ///< of the source points, within inlier_distance_m
  /// J^T W J at the result, in the tangent [rotation (rad, left), translation (m)]: the
  /// information of the pose.
  Matrix6d hessian = Matrix6d::Zero();
};

/// The cost, its gradient and its Gauss-Newton Hessian at T, in the left tangent [w, v]
/// (T <- (Exp(w) R, Exp(w) t + v)); exposed for the Jacobian's check.
struct VgicpLinearization {
  double cost = 0.0;
  Vector6d gradient = Vector6d::Zero();
  Matrix6d hessian = Matrix6d::Zero();
  size_t terms = 0;
};
VgicpLinearization linearize(const VoxelGaussians& target, const GaussianCloud& source,
                             const Eigen::Isometry3d& T);

/// How well `source` placed at T fits `target`'s voxels: fitness_m and inlier_fraction as in
/// VgicpResult. For comparing two poses of one scan on the same voxels (the refinement's
/// check of its result against the odometry's pose).
struct VgicpFit {
  double fitness_m = 0.0;
  double inlier_fraction = 0.0;
};
VgicpFit measure_fit(const VoxelGaussians& target, const GaussianCloud& source,
                     const Eigen::Isometry3d& T, double inlier_distance_m);

/// Registers `source` to the voxels of `target` from `guess` (target <- source), at their one
/// voxel size. Never NaN: a failed solve returns the guess with converged = false.
VgicpResult align_to_voxels(const VoxelGaussians& target, const GaussianCloud& source,
                            const Eigen::Isometry3d& guess, const VgicpSettings& settings = {});

/// The same from coarse voxels of `target` to fine ones (settings.voxel_sizes_m); the result
/// is the finest level's.
VgicpResult align(const GaussianCloud& target, const GaussianCloud& source,
                  const Eigen::Isometry3d& guess, const VgicpSettings& settings = {});

/// A target's voxels at every size of settings.voxel_sizes_m, and at fitness_voxel_m: made
/// once for a target that many sources are registered to.
struct VgicpTarget {
  VgicpTarget(const GaussianCloud& cloud, const VgicpSettings& settings);
  /// From voxels made beforehand: `levels` coarse to fine as settings.voxel_sizes_m, and the
  /// fitness voxels.
  VgicpTarget(std::vector<VoxelGaussians> levels, VoxelGaussians fitness);
  std::vector<VoxelGaussians> levels;  ///< coarse to fine
  VoxelGaussians fitness;
};

/// align() on a target made beforehand (with the same settings), from its level
/// `first_level` (0: the coarsest) on: a guess good to well within a finer level's voxel
/// needs no coarser one.
VgicpResult align(const VgicpTarget& target, const GaussianCloud& source,
                  const Eigen::Isometry3d& guess, const VgicpSettings& settings = {},
                  size_t first_level = 0);

/// One of several sources registered together: the correction found moves each by its share
/// of it (a drift that grows along a stretch of scans: share 0 at its start, 1 at its end).
struct SharedSource {
  const GaussianCloud* cloud = nullptr;
  Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
  double share = 1.0;
};

struct SharedVgicpResult {
  std::vector<Eigen::Isometry3d> poses;  ///< each source's (target <- source)
  /// The steps of the solve, in the left tangent of the target's frame: apply_steps() gives
  /// any other pose its share of the correction.
  std::vector<Vector6d> steps;
  bool converged = false;
  int iterations = 0;
  VgicpFit guess_fit;   ///< all sources at their guesses, on the fitness voxels
  VgicpFit result_fit;  ///< at the result
  /// Directions of the correction left at the guesses as too weakly constrained
  /// (min_constraint_ratio), and the weakest direction's share of the strongest.
  int weak_directions = 0;
  double weakest_ratio = 1.0;
};

/// Registers `sources` to `target` together, coarse to fine: one correction, shared out.
/// Rotations turn about the target frame's origin: put it near the sources. Never NaN: a
/// failed solve gives the guesses with converged = false.
SharedVgicpResult align_shared(const VgicpTarget& target, const std::vector<SharedSource>& sources,
                               const VgicpSettings& settings = {});

/// `guess` moved by its share of the steps of align_shared.
Eigen::Isometry3d apply_steps(const Eigen::Isometry3d& guess, const std::vector<Vector6d>& steps,
                              double share);

}  // namespace featsense::slam::refine
