#include "featsense/slam/refine/segment_refiner.hpp"

#include <algorithm>

namespace featsense::slam::refine {

RefineSettings from_config(const config::Config& config) {
  RefineSettings settings;
  settings.distance_m = config.refine.distance_m;
  settings.voxel_m = config.refine.voxel_m;
  settings.max_scans = static_cast<size_t>(config.refine.max_scans);
  settings.vgicp = stretch_vgicp(settings.voxel_m);
  settings.vgicp.min_constraint_ratio = config.refine.min_constraint_ratio;
  return settings;
}

}  // namespace featsense::slam::refine
