#pragma once
// The horizontal distance of a point from its beam's origin, the one rule by which a point's
// elevation is measured (organize.cpp, cloud/sensor_guess.cpp).

#include <cmath>

namespace featsense::slam {

/// The horizontal distance of (x, y) from the beam origin, `beam_origin_offset_m` out from
/// the lidar origin along the point's azimuth (Ouster sensors): from the lidar origin, a
/// point 1 m away on an OS1-128's top beam seems 0.35 degrees (a whole beam spacing) lower
/// than its beam. Points nearer than the offset keep their distance from the lidar origin.
inline double horizontal_from_beam_origin(double x, double y, double beam_origin_offset_m) {
  const double horizontal = std::sqrt(x * x + y * y);
  return horizontal > beam_origin_offset_m ? horizontal - beam_origin_offset_m : horizontal;
}

}  // namespace featsense::slam
