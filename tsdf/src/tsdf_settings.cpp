#include "featsense/tsdf/tsdf_settings.hpp"

#include <algorithm>
#include <cmath>

#include "featsense/tsdf/local_map_shift.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::tsdf {
namespace {

/// voxel / (2 x the coarsest angle between neighbouring rays): nearer than that, rays of
/// every second beam and column are still at most a voxel apart (TsdfSettings).
/// 0 for a model without beams or columns.
float dense_range(float voxel_size_m, const config::SensorModel& sensor) {
  if (sensor.beams < 2 || sensor.columns < 1) return 0.0f;
  constexpr double kPi = 3.14159265358979323846;
  double widest = 2.0 * kPi / static_cast<double>(sensor.columns);
  if (sensor.elevation_rad.size() == static_cast<size_t>(sensor.beams)) {
    for (size_t b = 1; b < sensor.elevation_rad.size(); ++b) {
      widest = std::max(widest, std::abs(sensor.elevation_rad[b - 1] - sensor.elevation_rad[b]));
    }
  } else {
    widest = std::max(widest, sensor.vertical_fov_rad() / static_cast<double>(sensor.beams - 1));
  }
  if (!(widest > 0.0)) return 0.0f;
  return static_cast<float>(static_cast<double>(voxel_size_m) / (2.0 * widest));
}

}  // namespace

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
  s.map_size_m = detail::to_float_size(map.size_m);
  if (map.vertical_interpolation && sensor.beams > 1) {
    s.interpolation_slope =
        static_cast<float>(std::tan(sensor.vertical_fov_rad() / static_cast<double>(sensor.beams)));
  }
  if (map.sparse_carving) s.dense_range_m = dense_range(s.voxel_size_m, sensor);
  s.carve_free_space = map.carve_free_space;
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
