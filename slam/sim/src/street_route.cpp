#include "street_route.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace featsense::slam {
namespace {

using P = Eigen::Vector2d;

/// The right of a direction of travel (x forward, y left).
P right_of(const P& d) { return P(d.y(), -d.x()); }

/// Points from a (excluded) to b (included), at most `spacing` apart. By value: `a` is often
/// out->back(), which the first push_back may move.
void add_straight(P a, P b, double spacing, std::vector<P>* out) {
  const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing)));
  for (int k = 1; k <= steps; ++k) out->push_back(a + (b - a) * (static_cast<double>(k) / steps));
}

}  // namespace

std::vector<P> street_route(const std::vector<P>& corners, const RouteShape& shape) {
  if (corners.size() < 2) throw std::invalid_argument("street route: needs two corners");
  std::vector<P> directions;
  for (size_t k = 1; k < corners.size(); ++k) {
    const P step = corners[k] - corners[k - 1];
    if ((step.x() != 0.0) == (step.y() != 0.0))
      throw std::invalid_argument("street route: leg " + std::to_string(k) +
                                  " is not parallel to an axis");
    directions.push_back(step.normalized());
  }
  const double r = shape.turn_radius_m;
  std::vector<P> out = {corners.front() + shape.lane_offset_m * right_of(directions.front())};
  for (size_t k = 1; k + 1 < corners.size(); ++k) {
    const P& d0 = directions[k - 1];
    const P& d1 = directions[k];
    if (d0.dot(d1) > 0.5) continue;  // straight on
    if (d0.dot(d1) < -0.5)
      throw std::invalid_argument("street route: turns back at corner " + std::to_string(k));
    // Where the two lanes cross, and the arc of radius r tangent to both: from c - r d0
    // to c + r d1 about the centre c - r d0 + r d1.
    const P c = corners[k] + shape.lane_offset_m * (right_of(d0) + right_of(d1));
    const P start = c - r * d0;
    if ((start - out.back()).dot(d0) < 0.0)
      throw std::invalid_argument("street route: leg " + std::to_string(k) +
                                  " is too short for its turns");
    add_straight(out.back(), start, shape.spacing_m, &out);
    const P centre = start + r * d1;
    const int steps = std::max(2, static_cast<int>(std::ceil(0.5 * M_PI * r / shape.spacing_m)));
    for (int s = 1; s <= steps; ++s) {
      const double angle = 0.5 * M_PI * s / steps;
      out.push_back(centre - r * std::cos(angle) * d1 + r * std::sin(angle) * d0);
    }
  }
  const P end = corners.back() + shape.lane_offset_m * right_of(directions.back());
  add_straight(out.back(), end, shape.spacing_m, &out);
  return out;
}

}  // namespace featsense::slam
