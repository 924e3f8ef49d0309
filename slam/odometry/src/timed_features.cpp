#include "timed_features.hpp"

#include "featsense/slam/odometry/voxel_filter.hpp"

namespace featsense::slam::odometry {
namespace {

void deskew_points(const std::vector<Eigen::Vector3f>& raw, const std::vector<float>& times,
                   const SweepMotion& sweep, std::vector<Eigen::Vector3f>& out) {
  for (size_t i = 0; i < raw.size(); ++i) {
    const Eigen::Isometry3d part = sweep.at(static_cast<double>(times[i]));
    out[i] = (part * raw[i].cast<double>()).cast<float>();
  }
}

}  // namespace

TimedFeatures voxel_filtered(const FeatureSet& features, double edge_voxel_m,
                             double surface_voxel_m) {
  TimedFeatures out;
  out.edges = voxel_filter(features.edges, features.edge_time_s, edge_voxel_m, &out.edge_time_s);
  out.surfaces = voxel_filter(features.surfaces, features.surface_time_s, surface_voxel_m,
                              &out.surface_time_s);
  return out;
}

TimedFeatures deskewed(const TimedFeatures& raw, const SweepMotion& sweep) {
  TimedFeatures out = raw;
  if (!sweep.moving()) return out;
  deskew_points(raw.edges, raw.edge_time_s, sweep, out.edges);
  deskew_points(raw.surfaces, raw.surface_time_s, sweep, out.surfaces);
  return out;
}

}  // namespace featsense::slam::odometry
