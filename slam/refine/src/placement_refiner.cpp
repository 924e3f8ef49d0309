#include "featsense/slam/refine/placement_refiner.hpp"

#include <chrono>
#include <utility>

#include "featsense/slam/refine/refinement_cloud.hpp"
#include "featsense/slam/trajectory/pose_interpolation.hpp"

namespace featsense::slam::refine {

PlacementRefiner::PlacementRefiner(const RefineSettings& settings)
    : settings_(settings), refiner_(settings) {}

std::vector<ScanPlacement> PlacementRefiner::add(const Scan& scan, ScanPlacement placement,
                                                 bool without_cloud) {
  std::vector<ScanPlacement> out;
  if (!started_) {
    started_ = true;
    if (!placement.deskewed()) {
      first_scan_ = scan;
      first_placement_ = std::move(placement);
      return out;
    }
  }
  if (first_scan_) {
    // The motion from the first scan to this one, over the time between them, is the first
    // scan's motion too (constant velocity, as the odometry assumes).
    ScanPlacement& first = *first_placement_;
    const double period_s = static_cast<double>(placement.stamp_ns - first.stamp_ns) * 1e-9;
    if (period_s > 0.0 && placement.deskewed()) {
      const Eigen::Isometry3d motion = first.T_map_sensor.inverse() * placement.T_map_sensor;
      first.column_T_map_sensor = column_poses(*first_scan_, first.T_map_sensor, [&](double t) {
        return std::optional<Eigen::Isometry3d>(first.T_map_sensor *
                                                motion_fraction(motion, t / period_s));
      });
    }
    hold(*first_scan_, std::move(first), false, out);
    first_scan_.reset();
    first_placement_.reset();
  }
  hold(scan, std::move(placement), without_cloud, out);
  return out;
}

std::vector<ScanPlacement> PlacementRefiner::finish() {
  std::vector<ScanPlacement> out;
  if (first_scan_) {
    hold(*first_scan_, std::move(*first_placement_), false, out);
    first_scan_.reset();
    first_placement_.reset();
  }
  release(out);
  return out;
}

void PlacementRefiner::hold(const Scan& scan, ScanPlacement placement, bool without_cloud,
                            std::vector<ScanPlacement>& out) {
  GaussianCloud cloud;
  const bool needs_cloud = refiner_.needs_cloud(placement.T_map_sensor);
  if (needs_cloud && without_cloud) {
    ++clouds_skipped_;
  } else if (needs_cloud) {
    const auto start = std::chrono::steady_clock::now();
    cloud = refinement_cloud(scan, placement, settings_.voxel_m, settings_.neighbours);
    cloud_ms_.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
  }
  const Eigen::Isometry3d pose = placement.T_map_sensor;
  placements_.push_back(std::move(placement));
  if (refiner_.add(pose, std::move(cloud))) release(out);
}

void PlacementRefiner::release(std::vector<ScanPlacement>& out) {
  const std::vector<Eigen::Isometry3d> poses = refiner_.refine();
  for (size_t i = 0; i < poses.size() && i < placements_.size(); ++i) {
    ScanPlacement& placement = placements_[i];
    const Eigen::Isometry3d correction = poses[i] * placement.T_map_sensor.inverse();
    placement.T_map_sensor = poses[i];
    for (Eigen::Isometry3d& column : placement.column_T_map_sensor) column = correction * column;
    out.push_back(std::move(placement));
  }
  placements_.clear();
}

}  // namespace featsense::slam::refine
