#include "featsense/slam/sim/measurement_model.hpp"

#include <algorithm>
#include <cmath>

namespace featsense::slam {
namespace {

/// SplitMix64's finaliser: a bijective mix, so distinct keys give independent-looking bits.
uint64_t mix(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

uint64_t hash_key(uint64_t seed, uint64_t frame, uint32_t row, uint32_t col, uint32_t purpose) {
  uint64_t h = mix(seed);
  h = mix(h ^ frame);
  h = mix(h ^ ((static_cast<uint64_t>(row) << 32) | col));
  return mix(h ^ purpose);
}

double to_unit(uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

}  // namespace

MeasurementSettings MeasurementSettings::exact() {
  MeasurementSettings s;
  s.range_noise = false;
  s.intensity = false;
  s.dropouts = false;
  s.mixed_pixels = false;
  return s;
}

double hashed_uniform(uint64_t seed, uint64_t frame, uint32_t row, uint32_t col, uint32_t purpose) {
  return to_unit(hash_key(seed, frame, row, col, purpose));
}

double hashed_normal(uint64_t seed, uint64_t frame, uint32_t row, uint32_t col, uint32_t purpose) {
  const uint64_t h = hash_key(seed, frame, row, col, purpose);
  const double u1 = (static_cast<double>(h >> 11) + 1.0) * 0x1.0p-53;  // (0, 1]: log is finite
  const double u2 = to_unit(mix(h));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

double return_strength(const HitGeometry& hit, const MeasurementSettings& settings) {
  // Lidar equation for an extended Lambertian target: power ~ reflectance cos / range^2.
  const double r = std::max(hit.range_m, 1e-3);
  const double ratio = hit.max_range_m / r;
  return hit.reflectance * std::max(hit.cos_incidence, 0.0) / settings.reference_reflectance *
         ratio * ratio;
}

double range_sigma_m(const HitGeometry& hit, const MeasurementSettings& settings) {
  const double strength = return_strength(hit, settings);
  // Weak returns are noisier: the noise grows as 1/sqrt of the strength below 10x the
  // detection threshold.
  const double weakness = std::sqrt(10.0 / std::clamp(strength, 1e-6, 10.0));
  const double sigma =
      settings.sigma_min_m * (1.0 + hit.range_m / settings.sigma_range_scale_m) * weakness;
  return std::clamp(sigma, settings.sigma_min_m, settings.sigma_max_m);
}

bool drops_out(const HitGeometry& hit, const MeasurementSettings& settings, double u) {
  if (hit.cos_incidence <= std::cos(settings.grazing_limit_rad)) return true;
  if (hit.reflectance < settings.dark_reflectance &&
      u >= hit.reflectance / settings.dark_reflectance)
    return true;
  return return_strength(hit, settings) < 1.0;
}

float intensity_of(const HitGeometry& hit) {
  const double r = std::max(hit.range_m, 0.1);
  return static_cast<float>(1e4 * hit.reflectance * std::max(hit.cos_incidence, 0.0) / (r * r));
}

}  // namespace featsense::slam
