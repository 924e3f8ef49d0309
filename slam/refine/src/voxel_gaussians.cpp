#include "featsense/slam/refine/voxel_gaussians.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <stdexcept>

#include "featsense/slam/refine/voxel_key.hpp"

namespace featsense::slam::refine {

VoxelGaussians::VoxelGaussians(const GaussianCloud& cloud, double voxel_m) : voxel_m_(voxel_m) {
  if (!(voxel_m > 0.0)) throw std::invalid_argument("VoxelGaussians: the voxel must be > 0");
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d& p = cloud.points[i];
    const uint64_t key = voxel_key(static_cast<int64_t>(std::floor(p.x() / voxel_m)),
                                   static_cast<int64_t>(std::floor(p.y() / voxel_m)),
                                   static_cast<int64_t>(std::floor(p.z() / voxel_m)));
    VoxelGaussian& v = voxels_[key];
    v.mean += p;
    v.covariance += cloud.covariances[i];
    ++v.points;
  }
  finish();
}

VoxelGaussians::VoxelGaussians(const std::vector<VoxelGaussian>& parts, double voxel_m)
    : voxel_m_(voxel_m) {
  if (!(voxel_m > 0.0)) throw std::invalid_argument("VoxelGaussians: the voxel must be > 0");
  for (const VoxelGaussian& part : parts) {
    if (part.points <= 0) continue;
    const Eigen::Vector3d& p = part.mean;
    const uint64_t key = voxel_key(static_cast<int64_t>(std::floor(p.x() / voxel_m)),
                                   static_cast<int64_t>(std::floor(p.y() / voxel_m)),
                                   static_cast<int64_t>(std::floor(p.z() / voxel_m)));
    VoxelGaussian& v = voxels_[key];
    v.mean += part.points * part.mean;
    v.covariance += part.points * part.covariance;
    v.points += part.points;
  }
  finish();
}

void VoxelGaussians::finish() {
  for (auto& [key, v] : voxels_) {
    v.mean /= static_cast<double>(v.points);
    v.covariance /= static_cast<double>(v.points);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    eigen.computeDirect(v.covariance);
    v.normal = eigen.eigenvectors().col(0);
  }
}

const VoxelGaussian* VoxelGaussians::at(const Eigen::Vector3d& p) const {
  const auto it = voxels_.find(voxel_key(static_cast<int64_t>(std::floor(p.x() / voxel_m_)),
                                         static_cast<int64_t>(std::floor(p.y() / voxel_m_)),
                                         static_cast<int64_t>(std::floor(p.z() / voxel_m_))));
  return it != voxels_.end() ? &it->second : nullptr;
}

}  // namespace featsense::slam::refine
