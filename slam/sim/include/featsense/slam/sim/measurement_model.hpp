#pragma once
/// What a real LiDAR makes of a geometric hit: range noise, intensity and reflectivity,
/// drop-outs and mixed pixels. Every random draw comes from a hash of (seed, frame, row,
/// column, purpose), so a frame's values do not depend on threads or on other frames.

#include <cstdint>

namespace featsense::slam {

struct MeasurementSettings {
  uint64_t seed = 1;
  /// Range noise: Gaussian, truncated at 3 sigma, sigma from sigma_min_m (near, strong
  /// return) growing with range and with weak returns up to sigma_max_m. With the defaults
  /// the error bound is 3 sigma = 1.5 cm to 10 cm, the spread Ouster specifies.
  bool range_noise = true;
  double sigma_min_m = 0.005;
  double sigma_max_m = 0.10 / 3.0;
  double sigma_range_scale_m = 40.0;  ///< sigma doubles from near to this range
  /// Intensity (signal, falls with range and incidence) and reflectivity (the material's,
  /// 0..100 %) channels. When off, both channels hold the material reflectance x 100.
  bool intensity = true;
  /// Drop-outs: grazing incidence, dark surfaces, and returns too weak for their range.
  bool dropouts = true;
  double grazing_limit_rad = 1.48;     ///< about 85 deg: no return at or beyond
  double dark_reflectance = 0.05;      ///< below this, returns vanish with rising odds
  double reference_reflectance = 0.8;  ///< reaches the sensor's max range head-on
  /// Mixed pixels: where the range jumps between neighbouring columns by more than
  /// mixed_min_jump_m onto another surface (a point more than half that off this cell's
  /// plane), the foreground cell reports, with probability mixed_probability, a range
  /// between the two surfaces.
  bool mixed_pixels = true;
  double mixed_min_jump_m = 0.3;
  double mixed_probability = 0.5;

  /// All effects off: exact geometric ranges (reflectivity still written).
  static MeasurementSettings exact();
};

/// A uniform draw in [0, 1) from the key (seed, frame, row, col, purpose).
double hashed_uniform(uint64_t seed, uint64_t frame, uint32_t row, uint32_t col, uint32_t purpose);
/// A standard normal draw from the same kind of key (Box-Muller over two hashed uniforms).
double hashed_normal(uint64_t seed, uint64_t frame, uint32_t row, uint32_t col, uint32_t purpose);

/// A geometric hit as the sensor sees it.
struct HitGeometry {
  double range_m = 0.0;        ///< along the beam, metres
  double cos_incidence = 1.0;  ///< between the beam and the surface normal
  double reflectance = 0.5;    ///< the surface material's, 0..1
  double max_range_m = 120.0;  ///< the sensor's
};

/// The return strength relative to a head-on reference target at max range (>= 1 means
/// detectable at any range up to max; dimensionless).
double return_strength(const HitGeometry& hit, const MeasurementSettings& settings);

/// Standard deviation of the range noise for this hit, metres.
double range_sigma_m(const HitGeometry& hit, const MeasurementSettings& settings);

/// True when the hit gives no return (grazing, dark, too weak), decided by the draw `u`
/// in [0, 1).
bool drops_out(const HitGeometry& hit, const MeasurementSettings& settings, double u);

/// Signal-like intensity: reflectance x cos(incidence) / range^2, scaled so that a white
/// head-on target at 1 m gives 10000 (arbitrary sensor units, as Ouster's signal).
float intensity_of(const HitGeometry& hit);

}  // namespace featsense::slam
