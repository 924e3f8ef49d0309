#pragma once
// Which points are returns: the one rule every reader and organize() apply.

#include <Eigen/Core>

#include <cmath>

namespace featsense::slam {

/// |p| in metres when p is a return, else 0. Not returns: NaN or infinite coordinates, the
/// origin (how many drivers mark "no return"), and points whose norm overflows or
/// underflows in float (coordinates near 1e19 or 1e-23), which no sensor measures.
inline float return_range(const Eigen::Vector3f& p) {
  if (!p.allFinite()) return 0.0f;
  const float range = p.norm();
  return std::isfinite(range) && range > 0.0f ? range : 0.0f;
}

inline bool is_return(const Eigen::Vector3f& p) { return return_range(p) > 0.0f; }

}  // namespace featsense::slam
