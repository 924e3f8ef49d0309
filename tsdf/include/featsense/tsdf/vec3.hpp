#pragma once
/// A minimal 3-vector for code that runs on both host and device (Eigen stays out of CUDA
/// kernels: it compiles there but floods the build with warnings).

#include <cmath>
#include <cstdint>

#include "featsense/tsdf/host_device.hpp"

namespace featsense::tsdf {

struct Vec3 {
  float x = 0.0f;
  float y = 0.0f;
  float z = 0.0f;
};

struct Index3 {
  int32_t x = 0;
  int32_t y = 0;
  int32_t z = 0;
};

FEATSENSE_HD_INLINE Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
FEATSENSE_HD_INLINE Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
FEATSENSE_HD_INLINE Vec3 operator*(float s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
FEATSENSE_HD_INLINE float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
FEATSENSE_HD_INLINE Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
FEATSENSE_HD_INLINE float norm(Vec3 a) { return sqrtf(dot(a, a)); }

FEATSENSE_HD_INLINE float component(Vec3 v, int axis) {
  return axis == 0 ? v.x : (axis == 1 ? v.y : v.z);
}
FEATSENSE_HD_INLINE int32_t component(Index3 v, int axis) {
  return axis == 0 ? v.x : (axis == 1 ? v.y : v.z);
}

}  // namespace featsense::tsdf
