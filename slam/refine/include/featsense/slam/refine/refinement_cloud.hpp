#pragma once
/// A placed scan as the refinement registers it: its points deskewed into the sensor's frame
/// at the stamp, thinned to one point per voxel, each with its neighbourhood's covariance.

#include <Eigen/Core>

#include <vector>

#include "featsense/slam/refine/gaussian_cloud.hpp"
#include "featsense/slam/scan.hpp"
#include "featsense/slam/scan_locator.hpp"

namespace featsense::slam::refine {

/// The valid points of `scan`, each moved by the motion over the scan that `placement` gives
/// (column_T_map_sensor) into the sensor's frame at the stamp, reduced to the centroid of each
/// voxel of edge `voxel_m` (> 0).
std::vector<Eigen::Vector3f> voxel_centroids(const Scan& scan, const ScanPlacement& placement,
                                             double voxel_m);

/// voxel_centroids(), each with the covariance of its `neighbours` nearest.
GaussianCloud refinement_cloud(const Scan& scan, const ScanPlacement& placement, double voxel_m,
                               int neighbours);

}  // namespace featsense::slam::refine
