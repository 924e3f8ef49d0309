#pragma once
/// One point per voxel: the first one met is kept (the order is the input's), non-finite
/// points are dropped.

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace featsense::slam::odometry {

/// The voxel (edge `voxel_m`) holding `p`, packed in 63 bits (21 bits per axis, so unique
/// within +/- 2^20 voxels of the origin).
uint64_t voxel_key(const Eigen::Vector3f& p, float inverse_voxel);

std::vector<Eigen::Vector3f> voxel_filter(const std::vector<Eigen::Vector3f>& points,
                                          double voxel_m);

/// The same, keeping each kept point's time: `times` has one per point (or is empty, then
/// `kept_times` gets 0 for each).
std::vector<Eigen::Vector3f> voxel_filter(const std::vector<Eigen::Vector3f>& points,
                                          const std::vector<float>& times, double voxel_m,
                                          std::vector<float>* kept_times);

}  // namespace featsense::slam::odometry
