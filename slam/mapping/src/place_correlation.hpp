#pragma once
// Where near a guessed place a scan lies: the map's upright surfaces (walls, posts, the sides
// of cars: surface whose normal lies near the horizontal) and the scan's, drawn from above on
// a grid of metre cells and compared over every horizontal shift within reach and a few turns
// about the guess, the best few again on a finer grid. A place descriptor finds the right street,
// but often at a keyframe metres along it, farther than a registration slides from (a street's
// facades hold nothing along it until a gap or a corner is in view); the comparison's best shifts
// are the places worth registering from. Upright surfaces only: the ground matches at every shift
// and would drown the differences, and heights are left out so that a sensor carried lower than the
// one that made the map (a walker in a map made from a car) is compared alike.

#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

#include "featsense/slam/refine/gaussian_cloud.hpp"

namespace featsense::mapping {

struct PlaceCorrelationSettings {
  double cell_m = 1.0;
  /// Shifts searched each way from the guess, along x and along y.
  double reach_m = 24.0;
  /// The scan's points compared: within this horizontal distance of the sensor (beyond it a
  /// turn of a few degrees moves them by more than a cell).
  double scan_range_m = 30.0;
  /// Turns about the guess's heading tried (a descriptor's heading is good to half a sector).
  std::vector<double> turns_deg = {-4.0, -2.0, 0.0, 2.0, 4.0};
  /// The same turned by 180 degrees too: a street looks much alike both ways.
  bool both_ways = true;
  /// The best places returned, at least this far apart.
  size_t peaks = 2;
  double peak_separation_m = 4.0;
  /// The best few coarse places are searched again on a finer grid, within a cell of the
  /// coarse one and with finer turns about its heading: a place found to a metre and a couple
  /// of degrees can be a lane off for the registration, which then settles beside the street
  /// it should be in.
  size_t refined = 4;
  double fine_cell_m = 0.25;
  std::vector<double> fine_turns_deg = {-1.5, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5};
  /// A surface is upright where its normal's vertical part is at most this.
  double max_normal_z = 0.5;
  /// What a scan cell costs where the map saw through that column and found no upright
  /// surface in or next to it (the street where the scan has a parked car, a facade where
  /// the map has a gap): against a cell on the map's surface, which gains 1. Without it a
  /// street's long facades match at every shift along it nearly as well as at the true one.
  double free_cost = 0.5;
};

struct PlacePeak {
  Eigen::Isometry3d T_map_query = Eigen::Isometry3d::Identity();
  /// The share of the scan's upright cells that fall on the map's (on a cell next to one of
  /// the map's: half), less free_cost for each that falls where the map saw free space; at
  /// most 1.
  double score = 0.0;
};

/// The upright points of `cloud` (sensor frame), by its covariances' thinnest direction
/// turned into the map frame by `R_map_sensor`.
std::vector<Eigen::Vector3d> upright_points(const slam::refine::GaussianCloud& cloud,
                                            const Eigen::Matrix3d& R_map_sensor,
                                            double max_normal_z);

/// The best places near `guess` (T_map_query) for a scan whose upright points (sensor frame)
/// are `scan_upright`, against the map's upright surface at `map_upright` and the columns
/// the map observed at all at `map_observed` (horizontal positions, map frame): best first,
/// at most settings.peaks; empty where the scan has no upright point within range.
std::vector<PlacePeak> correlate_place(const std::vector<Eigen::Vector2f>& map_upright,
                                       const std::vector<Eigen::Vector2f>& map_observed,
                                       const std::vector<Eigen::Vector3d>& scan_upright,
                                       const Eigen::Isometry3d& guess,
                                       const PlaceCorrelationSettings& settings);

}  // namespace featsense::mapping
