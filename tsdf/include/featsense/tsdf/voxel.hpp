#pragma once
/// The voxel encoding and the update rules of the TSDF, shared by every backend.
///
/// A map voxel is 32 bits: a signed 16-bit value and an unsigned 16-bit weight, fixed point:
///   value  = round(d / tau * kValueScale), d the signed distance in metres, |d| <= tau, so
///            the resolution is tau / 32767 (18 micrometres at tau = 0.6 m);
///   weight = round(w * kWeightScale), w >= 0 the confidence (one full-weight measurement
///            adds 1.0), so the resolution is 1/64 and w can reach 1023.
/// weight 0 means never observed. Packed as value in the low half, weight in the high half.
///
/// Per scan, every ray proposes a candidate for each voxel it visits; the smallest |d| wins,
/// and a measured candidate always beats one from vertical interpolation. A candidate is
/// encoded as an unsigned key whose integer order is exactly that preference:
///   bit 31      1 = interpolated, 0 = measured
///   bits 30..16 |value|
///   bit 15      1 = negative value (between +v and -v of equal size the positive wins)
/// so the scan's winner is the integer minimum of all keys: one atomicMin on the GPU, a plain
/// compare and store on the CPU (each voxel is written by the one task that owns its sector),
/// and the result does not depend on the order of rays.
/// kEmptyCandidate (all ones) is larger than every key.
///
/// Fusion (paper eqs. 5-6) runs in integer arithmetic so that every backend gives the same
/// bits: g.v = round((g.v g.w + v.v v.w) / (g.w + v.w)), g.w = min(w_max, g.w + v.w).

#include <cstdint>

#include "featsense/tsdf/host_device.hpp"

namespace featsense::tsdf {

constexpr int32_t kValueScale = 32767;
constexpr int32_t kWeightScale = 64;
constexpr uint32_t kEmptyCandidate = 0xFFFFFFFFu;
constexpr uint32_t kUnobservedVoxel = 0u;  ///< value 0, weight 0

struct Voxel {
  int16_t value = 0;    ///< fixed point, see kValueScale
  uint16_t weight = 0;  ///< fixed point, see kWeightScale
};

FEATSENSE_HD_INLINE uint32_t pack(Voxel v) {
  return static_cast<uint32_t>(static_cast<uint16_t>(v.value)) |
         (static_cast<uint32_t>(v.weight) << 16);
}

FEATSENSE_HD_INLINE Voxel unpack(uint32_t bits) {
  Voxel v;
  v.value = static_cast<int16_t>(static_cast<uint16_t>(bits & 0xFFFFu));
  v.weight = static_cast<uint16_t>(bits >> 16);
  return v;
}

/// Signed distance (metres, any size) to fixed point, clamped to +/- tau.
FEATSENSE_HD_INLINE int32_t distance_to_fixed(float distance_m, float truncation_m) {
  float scaled = distance_m / truncation_m * static_cast<float>(kValueScale);
  if (scaled > static_cast<float>(kValueScale)) scaled = static_cast<float>(kValueScale);
  if (scaled < -static_cast<float>(kValueScale)) scaled = -static_cast<float>(kValueScale);
  // Round half away from zero, identically on host and device.
  return static_cast<int32_t>(scaled >= 0.0f ? scaled + 0.5f : scaled - 0.5f);
}

FEATSENSE_HD_INLINE float fixed_to_distance(int32_t value, float truncation_m) {
  return static_cast<float>(value) * truncation_m / static_cast<float>(kValueScale);
}

FEATSENSE_HD_INLINE float fixed_to_weight(uint32_t weight) {
  return static_cast<float>(weight) / static_cast<float>(kWeightScale);
}

FEATSENSE_HD_INLINE uint32_t make_candidate(int32_t value, bool interpolated) {
  const uint32_t magnitude = static_cast<uint32_t>(value < 0 ? -value : value);
  return (interpolated ? 0x80000000u : 0u) | (magnitude << 16) | (value < 0 ? 0x8000u : 0u);
}

/// The key of free space (+tau, measured), which every visit in front of the band proposes.
constexpr uint32_t kFreeSpaceKey = static_cast<uint32_t>(kValueScale) << 16;

FEATSENSE_HD_INLINE int32_t candidate_value(uint32_t key) {
  const int32_t magnitude = static_cast<int32_t>((key >> 16) & 0x7FFFu);
  return (key & 0x8000u) != 0u ? -magnitude : magnitude;
}

FEATSENSE_HD_INLINE bool candidate_interpolated(uint32_t key) { return (key & 0x80000000u) != 0u; }

/// The weight (fixed point) a scan gives its winning value: full weight in front of the
/// surface and up to one voxel behind it, then falling linearly to 0 at tau behind it, since
/// the space behind a surface was not seen and the measured surface may be a voxel off.
FEATSENSE_HD_INLINE uint32_t candidate_weight(int32_t value, int32_t falloff_start_fixed) {
  if (value >= -falloff_start_fixed) return static_cast<uint32_t>(kWeightScale);
  const int64_t remaining = static_cast<int64_t>(kValueScale) + value;  // 0 at -tau
  const int64_t span = static_cast<int64_t>(kValueScale) - falloff_start_fixed;
  if (remaining <= 0 || span <= 0) return 0u;
  return static_cast<uint32_t>((remaining * kWeightScale + span / 2) / span);
}

/// Division rounding half away from zero (the numerator may be negative).
FEATSENSE_HD_INLINE int64_t divide_rounded(int64_t numerator, int64_t denominator) {
  return numerator >= 0 ? (numerator + denominator / 2) / denominator
                        : -((-numerator + denominator / 2) / denominator);
}

/// Eqs. (5)-(6) of the paper in fixed point. `max_weight_fixed` = w_max * kWeightScale.
FEATSENSE_HD_INLINE Voxel fuse(Voxel map, int32_t value, uint32_t weight,
                               uint32_t max_weight_fixed) {
  if (weight == 0u) return map;
  const int64_t total = static_cast<int64_t>(map.weight) + weight;
  Voxel out;
  out.weight = static_cast<uint16_t>(total < max_weight_fixed ? total : max_weight_fixed);
  // The average of a value with itself, or with nothing, is that value: no division there
  // (most of the carved free space; a 64-bit division is a long routine on a GPU).
  if (map.weight == 0u || map.value == value) {
    out.value = static_cast<int16_t>(value);
    return out;
  }
  const int64_t numerator =
      static_cast<int64_t>(map.value) * map.weight + static_cast<int64_t>(value) * weight;
  out.value = static_cast<int16_t>(divide_rounded(numerator, total));
  return out;
}

/// A voxel of settled free space: +tau with the capped weight. Fusing +tau into it changes
/// nothing (the average of equal values, a weight already at w_max), so the integrators let
/// free-space candidates pass it by: much less work where the sensor keeps seeing the same
/// free space.
FEATSENSE_HD_INLINE uint32_t settled_free_voxel(uint32_t max_weight_fixed) {
  Voxel v;
  v.value = static_cast<int16_t>(kValueScale);
  v.weight = static_cast<uint16_t>(max_weight_fixed);
  return pack(v);
}

/// Whether a candidate passes settled free space by: +tau, which would change nothing, and an
/// interpolated one, a guess between beams that does not wear down space measured free w_max
/// times. (Passing +tau alone would change the map: in a scan where a ray measures a settled
/// voxel +tau and another interpolates it, the measured +tau wins and keeps the voxel; without
/// it, the interpolated value would.) Measured values nearer the surface still update it.
FEATSENSE_HD_INLINE bool passes_settled_by(int32_t value, bool interpolated) {
  return value == kValueScale || interpolated;
}

}  // namespace featsense::tsdf
