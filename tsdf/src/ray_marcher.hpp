#pragma once
// One ray's contribution to a scan's TSDF volume: a 3D DDA that visits every voxel the ray
// crosses from where it enters the local map to tau behind its end point, with the
// projective distance of each, and the vertical interpolation of the paper: march_ray, which
// the reference integrator and the tests walk rays with. The definitions it rests on (the
// ray's setup, setup_ray; the walk's ticks; interpolation) are shared with the walk both fast
// backends run (ray_walk.hpp), so all propose exactly the same candidates.

#include <cfloat>

#include "featsense/tsdf/local_map_geometry.hpp"
#include "featsense/tsdf/ray_batch.hpp"
#include "featsense/tsdf/vec3.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::tsdf::detail {

struct RayMarchParams {
  float truncation_m = 0.6f;
  /// tan(vertical beam spacing): the half-height of the interpolation band per metre of
  /// range (paper eq. 7-8); 0 turns interpolation off.
  float interpolation_slope = 0.0f;
  Vec3 up{0.0f, 0.0f, 1.0f};  ///< the sensor's z axis in the map frame
  /// Free space nearer to the ray's origin than this is left to other rays (sparse carving,
  /// TsdfSettings::dense_range_m); 0 = the ray carves all the way to the sensor.
  float carve_from_m = 0.0f;
};

/// Where a ray of carving level `level` starts to carve free space: dense_range / 2^level, so
/// that at any distance the rays that carve there are at most a voxel apart (0: all the
/// way); nowhere without free-space carving. A division by a power of two: exact, the same on
/// host and device.
FEATSENSE_HD_INLINE float carving_start(bool carve_free_space, float dense_range_m,
                                        uint32_t level) {
  if (!carve_free_space) return FLT_MAX;
  if (!(dense_range_m > 0.0f) || level >= kFullCarvingLevel) return 0.0f;
  return dense_range_m / static_cast<float>(1u << level);
}

/// Distance from the origin at which the walk back towards the sensor ends: where the ray
/// enters the map, or, for a ray that carves only beyond carve_from_m, two voxels before
/// that and before the truncation band. A voxel's centre is within 0.87 voxels of every
/// point where the ray crosses it, so every voxel with its centre in the band is still
/// visited, with the same candidate as by a full walk.
FEATSENSE_HD_INLINE float walk_end(float t_enter, float range, const RayMarchParams& params,
                                   float voxel_size_m) {
  if (!(params.carve_from_m > 0.0f)) return t_enter;
  const float band_start = range - params.truncation_m;
  const float nearer = params.carve_from_m < band_start ? params.carve_from_m : band_start;
  const float end = nearer - 2.0f * voxel_size_m;
  return end > t_enter ? end : t_enter;
}

/// A walk measures its way along the ray in ticks: integers, 2^-27 of the distance from the
/// walk's start to the ray's origin each, so a walk spans at most kWalkTicks. Sums of integers
/// do not depend on their order, so the j-th face crossing along an axis is first + j * delta
/// whether a walk steps to it face by face or computes it in one go, as ray_walk.hpp's jumps
/// across whole bricks do (sums of floats would round differently). The unit depends only on
/// where the walk starts, not on where it ends, so a walk that stops early (sparse carving)
/// crosses the same faces at the same ticks as the whole walk of its ray. A tick is under half a
/// micrometre for a ray of 60 m, finer than a float's rounding there.
constexpr int32_t kWalkTicks = 1 << 27;
/// Any t beyond the walk's end: only "later than the end" matters there (the walk stops).
constexpr int32_t kBeyondWalk = kWalkTicks + 1;

struct WalkClock {
  float ticks_per_metre;  ///< kWalkTicks / the distance from the walk's start to the origin

  /// t metres from the walk's start in ticks, rounded down, clamped to [0, kBeyondWalk].
  FEATSENSE_HD_INLINE int32_t ticks(float t_m) const {
    const float x = t_m * ticks_per_metre;
    if (!(x > 0.0f)) return 0;  // NaN too
    if (x > static_cast<float>(kWalkTicks)) return kBeyondWalk;
    return static_cast<int32_t>(x);
  }
};

/// Where a walk crosses the voxel faces along one axis: the first crossing and the spacing of
/// the next ones, in ticks (at least one, so that every step moves on), and the direction of
/// the step; an axis the walk runs parallel to is never crossed.
struct AxisCrossings {
  int32_t step;
  int32_t first;
  int32_t delta;
};

/// voxel: the walk's start voxel along the axis; origin and direction: the walk's start and
/// direction along it.
FEATSENSE_HD_INLINE AxisCrossings axis_crossings(float origin, float direction, int32_t voxel,
                                                 float voxel_size_m, const WalkClock& clock) {
  const auto spacing = [&](float metres) {
    const int32_t delta = clock.ticks(metres);
    return delta > 0 ? delta : 1;
  };
  if (direction > 0.0f) {
    return {1,
            clock.ticks(((static_cast<float>(voxel) + 1.0f) * voxel_size_m - origin) / direction),
            spacing(voxel_size_m / direction)};
  }
  if (direction < 0.0f) {
    return {-1, clock.ticks((static_cast<float>(voxel) * voxel_size_m - origin) / direction),
            spacing(-voxel_size_m / direction)};
  }
  return {0, kBeyondWalk, kBeyondWalk};
}

/// The paper's vertical interpolation (eq. 7-8) around a voxel of the band: the voxels
/// round(half_height / voxel) steps above and below its centre along `across`, those inside
/// the map, handed to visit_voxel(global index) nearest first, above before below.
template <typename VisitVoxel>
FEATSENSE_HD_INLINE void for_each_interpolated_voxel(const LocalMapGeometry& map, Vec3 centre,
                                                     Vec3 across, float half_height,
                                                     VisitVoxel&& visit_voxel) {
  const float vs = map.voxel_size_m;
  const int32_t reach = static_cast<int32_t>(half_height / vs);
  for (int32_t k = 1; k <= reach; ++k) {
    const float shift = static_cast<float>(k) * vs;
    const Index3 above = map.voxel_of(centre + shift * across);
    const Index3 below = map.voxel_of(centre - shift * across);
    if (map.contains(above)) visit_voxel(above);
    if (map.contains(below)) visit_voxel(below);
  }
}

/// Clips the segment origin + t * dir, t in [t0, t1], to the box [lo, hi]; false if it misses.
FEATSENSE_HD_INLINE bool clip_to_box(Vec3 origin, Vec3 dir, Vec3 lo, Vec3 hi, float& t0,
                                     float& t1) {
  for (int axis = 0; axis < 3; ++axis) {
    const float o = component(origin, axis);
    const float d = component(dir, axis);
    const float a = component(lo, axis);
    const float b = component(hi, axis);
    if (d == 0.0f) {
      if (o < a || o >= b) return false;
      continue;
    }
    float ta = (a - o) / d;
    float tb = (b - o) / d;
    if (ta > tb) {
      const float swap = ta;
      ta = tb;
      tb = swap;
    }
    if (ta > t0) t0 = ta;
    if (tb < t1) t1 = tb;
  }
  return t0 < t1;
}

/// A ray made ready for its walk: what every walk of it (march_ray, walk_ray; the CPU's and the
/// GPU's) starts from, computed once here, so that they all start from the same bits.
struct RaySetup {
  float range;            ///< from the origin to the end point (metres)
  Vec3 dir;               ///< unit, from the origin towards the end point
  bool interpolate;       ///< whether the ray fills voxels above and below it near the surface
  Vec3 across;            ///< the unit direction of that filling, where interpolate
  float t_start;          ///< the ray's t where the walk starts: tau behind the end point or
                          ///< where the ray leaves the map, whichever comes first
  WalkClock clock;        ///< the walk's ticks
  int32_t end_ticks;      ///< the walk's end (walk_end), in ticks from its start
  Index3 voxel;           ///< the walk's first voxel (global index; may lie outside the map)
  AxisCrossings axes[3];  ///< the walk's face crossings along x, y and z
};

/// Sets `ray` up for the ray from `origin` to `endpoint` (map frame, metres); false for a ray
/// that proposes nothing: NaN, zero or infinite (a NaN or absurd point or origin), or one that
/// misses the local map.
FEATSENSE_HD_INLINE bool setup_ray(Vec3 origin, Vec3 endpoint, const LocalMapGeometry& map,
                                   const RayMarchParams& params, RaySetup& ray) {
  const Vec3 delta = endpoint - origin;
  ray.range = norm(delta);
  if (!(ray.range > 0.0f && ray.range < 1.0e30f)) return false;
  ray.dir = (1.0f / ray.range) * delta;
  float t0 = 0.0f;
  float t1 = ray.range + params.truncation_m;
  if (!clip_to_box(origin, ray.dir, map.min_corner(), map.max_corner(), t0, t1)) return false;

  // Interpolation direction: int = d x (d x up), in the plane of the ray and the sensor's up.
  ray.across = cross(ray.dir, cross(ray.dir, params.up));
  const float across_length = norm(ray.across);
  ray.interpolate = params.interpolation_slope > 0.0f && across_length > 1e-6f;
  if (ray.interpolate) ray.across = (1.0f / across_length) * ray.across;

  // The walk goes from the far end back to the sensor (march_ray says why), measured in ticks
  // of the distance from its start to the origin.
  const float vs = map.voxel_size_m;
  const Vec3 walk_start = origin + t1 * ray.dir;
  const Vec3 walk_dir = -1.0f * ray.dir;
  const float walk_length = t1 - walk_end(t0, ray.range, params, vs);
  ray.t_start = t1;
  ray.clock = WalkClock{static_cast<float>(kWalkTicks) / t1};
  ray.end_ticks = ray.clock.ticks(walk_length);
  ray.voxel = map.voxel_of(walk_start);
  for (int axis = 0; axis < 3; ++axis) {
    ray.axes[axis] = axis_crossings(component(walk_start, axis), component(walk_dir, axis),
                                    component(ray.voxel, axis), vs, ray.clock);
  }
  return true;
}

/// Calls visit(linear_index, value_fixed, interpolated) for each candidate of the ray from `origin`
/// to `endpoint` (map frame, metres). Voxels outside the local map are never visited. The
/// plain statement of the rule: the reference integrator walks its rays with it; the fast
/// integrators run walk_ray (ray_walk.hpp), which proposes the same candidates with less work,
/// and the tests check it against this.
template <typename Visit>
FEATSENSE_HD_INLINE void march_ray(Vec3 origin, Vec3 endpoint, const LocalMapGeometry& map,
                                   const RayMarchParams& params, Visit&& visit) {
  RaySetup ray;
  if (!setup_ray(origin, endpoint, map, params, ray)) return;

  // Amanatides & Woo traversal from the far end back to the sensor. Every ray passes the
  // few voxels next to the sensor; walking towards them, rays arrive there at different
  // times and mostly find them already carved, instead of all contending for them at once.
  Index3 voxel = ray.voxel;
  int32_t step[3];
  int32_t t_next[3];  // ticks
  int32_t t_delta[3];
  for (int axis = 0; axis < 3; ++axis) {
    step[axis] = ray.axes[axis].step;
    t_next[axis] = ray.axes[axis].first;
    t_delta[axis] = ray.axes[axis].delta;
  }

  const float tau = params.truncation_m;
  int32_t t = 0;
  // Bounded by the number of voxels a segment can cross, so rounding can never loop forever.
  const int32_t max_steps = map.dim.x + map.dim.y + map.dim.z + 3;
  for (int32_t i = 0; i < max_steps && t <= ray.end_ticks; ++i) {
    if (map.contains(voxel)) {
      const Vec3 centre = map.centre_of(voxel);
      const float along = dot(centre - origin, ray.dir);
      const float distance = ray.range - along;
      if (distance >= -tau) {
        const int32_t value = distance_to_fixed(distance, tau);
        visit(map.linear(voxel), value, false);
        // Fill between the scan lines only near the surface: free space far in front is
        // carved by the rays themselves, and widening every ray there costs more than it gives.
        if (ray.interpolate && distance < tau) {
          for_each_interpolated_voxel(map, centre, ray.across, params.interpolation_slope * along,
                                      [&](Index3 g) { visit(map.linear(g), value, true); });
        }
      }
    }
    // Step into the neighbour across the nearest voxel face.
    int axis = 0;
    if (t_next[1] < t_next[axis]) axis = 1;
    if (t_next[2] < t_next[axis]) axis = 2;
    t = t_next[axis];
    t_next[axis] += t_delta[axis];
    if (axis == 0) voxel.x += step[0];
    if (axis == 1) voxel.y += step[1];
    if (axis == 2) voxel.z += step[2];
  }
}

}  // namespace featsense::tsdf::detail
