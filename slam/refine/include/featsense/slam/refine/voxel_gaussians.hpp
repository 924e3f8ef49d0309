#pragma once
/// The target of voxelized GICP: per voxel, the Gaussian aggregated from the points in it
/// (their mean, and the mean of their covariances, as VGICP defines it), found by hashing the
/// voxel of a query point.

#include <Eigen/Core>

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "featsense/slam/refine/gaussian_cloud.hpp"

namespace featsense::slam::refine {

struct VoxelGaussian {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  /// The covariance's thinnest direction: the normal of the surface where the voxel holds
  /// one, for the registration's fitness.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  int points = 0;
};

class VoxelGaussians {
 public:
  /// `voxel_m` > 0: the voxel edge, metres.
  VoxelGaussians(const GaussianCloud& cloud, double voxel_m);
  /// From parts summed beforehand (each: the mean of its points, the mean of their
  /// covariances, how many), e.g. the cells of a finer grid: each part goes to the voxel of
  /// its mean, weighted by its points, so that the voxels are those of its points.
  VoxelGaussians(const std::vector<VoxelGaussian>& parts, double voxel_m);

  /// The voxel holding `p`, where it holds points, else nullptr (nothing else: a neighbour's
  /// mean would pull the point towards a surface it does not lie on).
  const VoxelGaussian* at(const Eigen::Vector3d& p) const;

  size_t size() const { return voxels_.size(); }
  double voxel_m() const { return voxel_m_; }

 private:
  void finish();

  double voxel_m_;
  std::unordered_map<uint64_t, VoxelGaussian> voxels_;
};

}  // namespace featsense::slam::refine
