#include "featsense/slam/refine/refinement_cloud.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "featsense/slam/refine/voxel_key.hpp"

namespace featsense::slam::refine {

std::vector<Eigen::Vector3f> voxel_centroids(const Scan& scan, const ScanPlacement& placement,
                                             double voxel_m) {
  if (!(voxel_m > 0.0)) throw std::invalid_argument("refinement_cloud: the voxel must be > 0");
  const Eigen::Isometry3d T_sensor_map = placement.T_map_sensor.inverse();
  const bool deskew = placement.deskewed() &&
                      placement.column_T_map_sensor.size() == static_cast<size_t>(scan.cols);
  // Per column, the motion from when the column was measured to the stamp.
  std::vector<Eigen::Isometry3d> T_stamp_column;
  if (deskew) {
    T_stamp_column.reserve(placement.column_T_map_sensor.size());
    for (const Eigen::Isometry3d& T : placement.column_T_map_sensor)
      T_stamp_column.push_back(T_sensor_map * T);
  }
  struct Sum {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    int count = 0;
  };
  std::unordered_map<uint64_t, Sum> voxels;
  voxels.reserve(scan.valid_count() / 4 + 1);
  const double inverse_voxel = 1.0 / voxel_m;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = scan.index(row, col);
      if (!scan.valid[i] || !scan.xyz[i].allFinite()) continue;
      Eigen::Vector3d p = scan.xyz[i].cast<double>();
      if (deskew) p = T_stamp_column[static_cast<size_t>(col)] * p;
      Sum& sum = voxels[voxel_key_of(p, inverse_voxel)];
      sum.point += p;
      ++sum.count;
    }
  }
  std::vector<Eigen::Vector3f> centroids;
  centroids.reserve(voxels.size());
  for (const auto& [key, sum] : voxels)
    centroids.push_back((sum.point / static_cast<double>(sum.count)).cast<float>());
  return centroids;
}

GaussianCloud refinement_cloud(const Scan& scan, const ScanPlacement& placement, double voxel_m,
                               int neighbours) {
  return with_covariances(voxel_centroids(scan, placement, voxel_m), neighbours);
}

}  // namespace featsense::slam::refine
