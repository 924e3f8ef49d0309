#pragma once
// Where a saved map was seen from: the sensor's positions along the map's path. A surface
// the map holds is known as well as the range it was seen at allows: a beam's footprint grows
// with the range (across the beam: range times divergence), and the mapping's own attitude
// error moves a surface by range times angle. Both move a surface along its normal in
// proportion to how obliquely it was seen, so the ground tens of metres from the path, seen at
// a grazing angle, is the least sure part of a map (measured in the town: the localized height
// errs by 8.6 mm RMS within 5 m of the map's path and by 23.5 mm at 25-30 m).

#include <Eigen/Core>

#include <vector>

#include "featsense/mapping/saved_map.hpp"

namespace featsense::mapping {

class MapPath {
 public:
  /// Every session's poses (the keyframes' where a map keeps no trajectory), one kept per
  /// `spacing_m` travelled.
  MapPath(const SavedMap& saved, double spacing_m);
  explicit MapPath(std::vector<Eigen::Vector3d> positions) : positions_(std::move(positions)) {}

  const std::vector<Eigen::Vector3d>& positions() const { return positions_; }

 private:
  std::vector<Eigen::Vector3d> positions_;
};

/// The path's position nearest to each cell of a horizontal grid around a centre: from where a
/// surface there was seen closest (horizontally: a map's path runs on the ground).
class SeenFrom {
 public:
  /// A square grid of `cell_m` cells reaching `radius_m` from `centre`; path positions up to
  /// `reach_m` beyond it are looked at.
  SeenFrom(const MapPath& path, const Eigen::Vector3d& centre, double radius_m, double cell_m,
           double reach_m);

  /// The path's position nearest to `p` (horizontally, to its cell's centre); nullptr outside
  /// the grid or where no position lies within its reach.
  const Eigen::Vector3f* nearest(const Eigen::Vector3d& p) const;

 private:
  Eigen::Vector2d origin_;
  double cell_m_;
  int cells_ = 0;  ///< along each side
  /// Per cell, row by row; empty where no path position lies within the reach.
  std::vector<Eigen::Vector3f> nearest_;
};

/// The standard deviation along `normal` of a surface at `point` seen from `seen_from`, where
/// the map's surfaces are known to `angle_sigma_rad` of the range they were seen at across the
/// line of sight: angle * |normal x (point - seen_from)|.
double surface_sigma(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                     const Eigen::Vector3d& seen_from, double angle_sigma_rad);

}  // namespace featsense::mapping
