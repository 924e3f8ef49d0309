#include "featsense/slam/refine/segment_refiner.hpp"

#include <algorithm>

namespace featsense::slam::refine {

RefineSettings from_config(const config::Config& config) {
  RefineSettings settings;
  settings.distance_m = config.refine.distance_m;
  settings.voxel_m = config.refine.voxel_m;
  settings.max_scans = static_cast<size_t>(config.refine.max_scans);
  // Voxels of the target twice the points' spacing, then equal to it: finer ones would hold
  // single points, with no surface to register to.
  settings.vgicp.voxel_sizes_m = {2.0 * settings.voxel_m, settings.voxel_m};
  settings.vgicp.fitness_voxel_m = std::max(0.5, 2.0 * settings.voxel_m);
  return settings;
}

}  // namespace featsense::slam::refine
