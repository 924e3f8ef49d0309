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

/// Registers `source` to the voxels of `target` from `guess` (target <- source), at their one
/// voxel size. Never NaN: a failed solve returns the guess with converged = false.
VgicpResult align_to_voxels(const VoxelGaussians& target, const GaussianCloud& source,
                            const Eigen::Isometry3d& guess, const VgicpSettings& settings = {});

/// The same from coarse voxels of `target` to fine ones (settings.voxel_sizes_m); the result
/// is the finest level's.
VgicpResult align(const GaussianCloud& target, const GaussianCloud& source,
                  const Eigen::Isometry3d& guess, const VgicpSettings& settings = {});

}  // namespace featsense::slam::refine
