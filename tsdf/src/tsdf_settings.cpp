#include "featsense/tsdf/tsdf_settings.hpp"

#include <cmath>

#include "featsense/tsdf/local_map_shift.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::tsdf {

Index3 TsdfSettings::map_dim() const {
  int32_t dim[3];
  for (int axis = 0; axis < 3; ++axis) {
    const double voxels = std::ceil(map_size_m[static_cast<size_t>(axis)] / voxel_size_m);
    int32_t bricks = static_cast<int32_t>(std::ceil(voxels / kBrickSize));
    if (bricks % 2 == 0) ++bricks;
    dim[axis] = bricks * kBrickSize;
  }
  return {dim[0], dim[1], dim[2]};
}

uint32_t TsdfSettings::max_weight_fixed() const {
  return static_cast<uint32_t>(std::lround(max_weight * static_cast<float>(kWeightScale)));
}

int32_t TsdfSettings::falloff_start_fixed() const {
  return distance_to_fixed(voxel_size_m, truncation_m);
}

TsdfSettings TsdfSettings::from_config(const config::MapConfig& map,
                                       const config::SensorModel& sensor) {
  TsdfSettings s;
  s.voxel_size_m = static_cast<float>(map.voxel_size_m);
  s.truncation_m = static_cast<float>(map.truncation_m);
  s.max_weight = static_cast<float>(map.max_weight);
  for (size_t axis = 0; axis < 3; ++axis) s.map_size_m[axis] = static_cast<float>(map.size_m[axis]);
  if (map.vertical_interpolation && sensor.beams > 1) {
    s.interpolation_slope =
        static_cast<float>(std::tan(sensor.vertical_fov_rad() / static_cast<double>(sensor.beams)));
  }
  return s;
}

LocalMapGeometry centred_geometry(const TsdfSettings& settings, Vec3 centre_m) {
  LocalMapGeometry g;
  g.voxel_size_m = settings.voxel_size_m;
  g.dim = settings.map_dim();
  g.origin = centred_origin(g, centre_m);
  return g;
}

}  // namespace featsense::tsdf
