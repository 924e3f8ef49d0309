#pragma once
/// Waypoints of a drive along streets: legs parallel to the axes between corner points, kept
/// to one side of the centre line (a lane), corners rounded with a fixed radius, sampled
/// densely enough that the simulator's spline through them keeps to the lanes and arcs;
/// private to slam/sim.

#include <Eigen/Core>

#include <vector>

namespace featsense::slam {

struct RouteShape {
  double lane_offset_m = 0.0;  ///< to the right of the centre line (right-hand traffic)
  double turn_radius_m = 7.0;  ///< of every corner, in the lane
  double spacing_m = 2.0;      ///< at most between waypoints
};

/// Waypoints (x, y; metres) through `corners`, the centre lines' turning points and ends.
/// Consecutive corners must differ in x or in y only; a route may go straight on through a
/// corner or turn by 90 degrees there, never back. Throws std::invalid_argument otherwise,
/// or when a leg is too short for the turns at its ends.
std::vector<Eigen::Vector2d> street_route(const std::vector<Eigen::Vector2d>& corners,
                                          const RouteShape& shape);

}  // namespace featsense::slam
