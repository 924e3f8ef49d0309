#pragma once
/// What a TSDF integrator needs to know, in plain numbers (built from the config and the
/// sensor model by from_config()).

#include <array>
#include <cstdint>

#include "featsense/config/config.hpp"
#include "featsense/config/sensor_model.hpp"
#include "featsense/tsdf/local_map_geometry.hpp"

namespace featsense::tsdf {

namespace detail {
/// The map settings of config/default.yaml, where TsdfSettings' defaults come from.
inline constexpr config::MapConfig kDefaultMap{};

/// A map size in metres as the floats TsdfSettings keeps.
constexpr std::array<float, 3> to_float_size(const std::array<double, 3>& size_m) {
  return {static_cast<float>(size_m[0]), static_cast<float>(size_m[1]),
          static_cast<float>(size_m[2])};
}
}  // namespace detail

/// Default-constructed: the defaults of config::MapConfig (config/default.yaml) as
/// from_config converts them, without a sensor (no interpolation, every ray carves).
struct TsdfSettings {
  float voxel_size_m = static_cast<float>(detail::kDefaultMap.voxel_size_m);
  float truncation_m = static_cast<float>(detail::kDefaultMap.truncation_m);
  float max_weight = static_cast<float>(detail::kDefaultMap.max_weight);
  std::array<float, 3> map_size_m = detail::to_float_size(detail::kDefaultMap.size_m);
  /// tan of the vertical angle between two beams (vfov / beams, paper eq. 7); 0 = no
  /// vertical interpolation.
  float interpolation_slope = 0.0f;
  /// Before ray marching, keep only the first end point (in scan order) of each voxel of
  /// the local map; end points outside it are all kept. Rays to one voxel propose nearly
  /// the same values, so this saves work at a loss below the voxel size.
  bool reduce_points_per_voxel = true;
  /// Sparse carving: within this distance of the sensor neighbouring rays are less than half
  /// a voxel apart, and every voxel would be carved by several of them. There only a
  /// lattice of rays carves free space: a ray of carving level L (RayBatch::carving_level,
  /// its beam and column multiples of 2^L) from dense_range_m / 2^L outwards, so the rays
  /// that carve at any distance are at most a voxel apart, as all rays are at twice this
  /// distance. The truncation band is
  /// always walked by every ray. 0: every ray carves all the way to the sensor.
  float dense_range_m = 0.0f;
  /// false: rays walk only the truncation band around their end points (and two voxels in
  /// front of it), free space is not carved. Several times faster, but what moves through
  /// the scene leaves its surfaces in the map.
  bool carve_free_space = detail::kDefaultMap.carve_free_space;

  /// Voxels per axis: the size rounded up to whole bricks and to an odd count of bricks, so
  /// that the sensor sits in the centre brick.
  Index3 map_dim() const;
  /// The fixed-point weight cap (max_weight * kWeightScale).
  uint32_t max_weight_fixed() const;
  /// Where the weight of a scan starts to fall off behind the surface, fixed point (one voxel).
  int32_t falloff_start_fixed() const;

  /// Settings of config.map, interpolation from the sensor's vertical field of view and beams,
  /// the dense range from its coarsest angle between neighbouring beams or columns.
  static TsdfSettings from_config(const config::MapConfig& map, const config::SensorModel& sensor);
};

/// The local map geometry of `settings`, centred on the brick that holds `centre_m`.
LocalMapGeometry centred_geometry(const TsdfSettings& settings, Vec3 centre_m);

}  // namespace featsense::tsdf
