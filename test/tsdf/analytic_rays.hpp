#pragma once
// Scans of analytic surfaces for the TSDF tests: the beams of a sensor model cast from one
// origin against a plane or a sphere, exact to float precision.

#include <cmath>
#include <optional>

#include "featsense/config/sensor_model.hpp"
#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::tsdf::test {

inline Vec3 make_vec(double x, double y, double z) {
  return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
}

/// Casts every beam of `sensor` (no rotation, columns clockwise from +x) from `origin` and
/// keeps the hits that `intersect(origin, direction)` returns within the sensor's range.
template <typename Intersect>
RayBatch cast_rays(const config::SensorModel& sensor, const double origin[3],
                   Intersect&& intersect) {
  RayBatch rays;
  rays.origins_m.push_back(make_vec(origin[0], origin[1], origin[2]));
  for (int col = 0; col < sensor.columns; ++col) {
    const double azimuth = -2.0 * M_PI * col / sensor.columns;
    for (int row = 0; row < sensor.beams; ++row) {
      const double elevation = sensor.elevation_rad[static_cast<size_t>(row)];
      const double d[3] = {std::cos(elevation) * std::cos(azimuth),
                           std::cos(elevation) * std::sin(azimuth), std::sin(elevation)};
      const std::optional<double> t = intersect(origin, d);
      if (!t || *t < sensor.min_range_m || *t > sensor.max_range_m) continue;
      rays.endpoints_m.push_back(
          make_vec(origin[0] + *t * d[0], origin[1] + *t * d[1], origin[2] + *t * d[2]));
    }
  }
  return rays;
}

/// Hit of the plane n . x = offset (n unit), from its positive side.
inline auto plane(const double n[3], double offset) {
  return [=](const double o[3], const double d[3]) -> std::optional<double> {
    const double denom = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    if (denom >= -1e-9) return std::nullopt;  // parallel or seen from behind
    const double t = (offset - (n[0] * o[0] + n[1] * o[1] + n[2] * o[2])) / denom;
    return t > 0.0 ? std::optional<double>(t) : std::nullopt;
  };
}

/// First hit of the sphere |x - c| = r from outside.
inline auto sphere(const double c[3], double r) {
  return [=](const double o[3], const double d[3]) -> std::optional<double> {
    const double oc[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
    const double b = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
    const double cc = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
    const double disc = b * b - cc;
    if (disc < 0.0) return std::nullopt;
    const double t = -b - std::sqrt(disc);
    return t > 0.0 ? std::optional<double>(t) : std::nullopt;
  };
}

}  // namespace featsense::tsdf::test
