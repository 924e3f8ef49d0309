#pragma once
/// A scan's features as the registration uses them: voxel-filtered, each point with its
/// time after the scan's stamp, and moved to the stamp with a motion (deskewing).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

#include "featsense/slam/feature_set.hpp"
#include "featsense/slam/trajectory/sweep_motion.hpp"

namespace featsense::slam::odometry {

struct TimedFeatures {
  std::vector<Eigen::Vector3f> edges;
  std::vector<float> edge_time_s;
  std::vector<Eigen::Vector3f> surfaces;
  std::vector<float> surface_time_s;

  bool empty() const { return edges.empty() && surfaces.empty(); }
};

/// One point per voxel of each kind (odometry.edge_voxel, surface_voxel), with its time.
TimedFeatures voxel_filtered(const FeatureSet& features, double edge_voxel_m,
                             double surface_voxel_m);

/// The points in the sensor frame at the stamp: a point measured t after the stamp moved by
/// sweep.at(t). A sweep that is not moving leaves the points as measured.
TimedFeatures deskewed(const TimedFeatures& raw, const SweepMotion& sweep);

}  // namespace featsense::slam::odometry
