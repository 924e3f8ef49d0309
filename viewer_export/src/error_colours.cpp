#include "featsense/viewer_export/error_colours.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "internal/plan_overlay.hpp"

namespace featsense::viewer_export {
namespace {

constexpr uint8_t kNoDistanceGrey = 128;

}  // namespace

std::array<uint8_t, 3> signed_distance_colour(float signed_distance_m, float saturation_m) {
  if (std::isnan(signed_distance_m)) return {kNoDistanceGrey, kNoDistanceGrey, kNoDistanceGrey};
  // Infinite distances saturate like large ones; so does every non-zero one where the
  // saturation is not positive.
  const float sign = static_cast<float>((signed_distance_m > 0.0f) - (signed_distance_m < 0.0f));
  const float scaled = saturation_m > 0.0f ? signed_distance_m / saturation_m : sign;
  const float t = std::clamp(scaled, -1.0f, 1.0f);
  // The other two channels fade together, so that the hue stays pure red or pure blue.
  const uint8_t fade = static_cast<uint8_t>(std::lround(255.0f * (1.0f - std::abs(t))));
  if (t >= 0.0f) return {255, fade, fade};
  return {fade, fade, 255};
}

std::vector<Eigen::Matrix<uint8_t, 3, 1>> signed_distance_colours(
    const std::vector<float>& signed_distance_m, float saturation_m) {
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> colours;
  colours.reserve(signed_distance_m.size());
  for (const float d : signed_distance_m) {
    const std::array<uint8_t, 3> rgb = signed_distance_colour(d, saturation_m);
    colours.emplace_back(rgb[0], rgb[1], rgb[2]);
  }
  return colours;
}

PlanVertexColours signed_distance_plan_colours(const std::vector<float>& signed_distance_m,
                                               float saturation_m) {
  PlanVertexColours colours;
  colours.rgb = signed_distance_colours(signed_distance_m, saturation_m);
  const std::string limit = length_text(saturation_m);
  colours.low = "behind -" + limit;
  colours.high = "+" + limit + " in front";
  colours.ramp = [saturation_m](double t) {
    return signed_distance_colour(static_cast<float>((2.0 * t - 1.0) * saturation_m), saturation_m);
  };
  return colours;
}

}  // namespace featsense::viewer_export
