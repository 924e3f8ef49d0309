#pragma once
// Where the plan view cuts the map: a height per place, above which nothing is drawn.

#include <Eigen/Core>

#include <limits>
#include <string>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"
#include "internal/plan_frame.hpp"

namespace featsense::viewer_export {

/// A cut height over the plan, held on a coarse grid of cells (a metre or so) and interpolated
/// between their centres, so that looking it up per pixel costs nothing.
class CutHeightField {
 public:
  /// The same height everywhere (+inf: nothing is cut).
  static CutHeightField fixed(double height_m, std::string rule);

  /// A cut that follows the sensor: margin_m above the highest of `positions_m` within
  /// radius_m (horizontally) of a place, else above the nearest position. The highest, not the
  /// nearest nor the mean: where a path passes a place on two storeys (up the stairs and back
  /// below), the plan shows the upper one whole rather than a patchwork of both; on a ramp the
  /// cut rises with the path, so a car park's lower deck is not hidden under its upper one.
  static CutHeightField along_paths(const std::vector<Eigen::Vector3d>& positions_m,
                                    double margin_m, double radius_m, const PlanFrame& frame);

  /// Without a path: the floor's height plus 1.5 m (at most half way to the ceiling), where
  /// the mesh has a ceiling above its main floor (horizontal_levels.hpp); without one
  /// (outdoors), nothing is cut, since the only global height that would suit a hilly place is
  /// none.
  static CutHeightField from_floors_and_ceilings(const mesh::TriangleMesh& mesh);

  double at(double x_m, double y_m) const;
  double lowest_m() const { return lowest_m_; }
  double highest_m() const { return highest_m_; }
  const std::string& rule() const { return rule_; }

 private:
  int columns_ = 1;
  int rows_ = 1;
  double cell_m_ = 1.0;
  double min_x_m_ = 0.0;
  double max_y_m_ = 0.0;
  std::vector<double> cells_{std::numeric_limits<double>::infinity()};  ///< rows from the top
  double lowest_m_ = std::numeric_limits<double>::infinity();
  double highest_m_ = std::numeric_limits<double>::infinity();
  std::string rule_;
};

}  // namespace featsense::viewer_export
