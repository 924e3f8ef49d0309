#include "timed_features.hpp"

#include "featsense/slam/odometry/voxel_filter.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"

namespace featsense::slam::odometry {
namespace {

void deskew_points(const std::vector<Eigen::Vector3f>& raw, const std::vector<float>& times,
                   const Eigen::Isometry3d& motion, double period_s,
                   std::vector<Eigen::Vector3f>& out) {
  for (size_t i = 0; i < raw.size(); ++i) {
    const double s = static_cast<double>(times[i]) / period_s;
    const Eigen::Isometry3d part = motion_fraction(motion, s);
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

TimedFeatures deskewed(const TimedFeatures& raw, const Eigen::Isometry3d& motion, double period_s) {
  TimedFeatures out = raw;
  if (!(period_s > 0.0)) return out;
  deskew_points(raw.edges, raw.edge_time_s, motion, period_s, out.edges);
  deskew_points(raw.surfaces, raw.surface_time_s, motion, period_s, out.surfaces);
  return out;
}

}  // namespace featsense::slam::odometry
