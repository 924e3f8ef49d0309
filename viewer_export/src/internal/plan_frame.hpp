#pragma once
// Where the plan's pixels lie in the map: north up, pixel (0, 0) at the top-left corner.

#include <cmath>
#include <cstddef>

namespace featsense::viewer_export {

struct PlanFrame {
  int width_px = 0;
  int height_px = 0;
  double pixel_size_m = 1.0;
  double min_x_m = 0.0;  ///< the left edge, map frame
  double max_y_m = 0.0;  ///< the top edge

  size_t pixels() const { return static_cast<size_t>(width_px) * static_cast<size_t>(height_px); }
  size_t index(int column, int row) const {
    return static_cast<size_t>(row) * static_cast<size_t>(width_px) + static_cast<size_t>(column);
  }
  /// Continuous pixel coordinates of a map point: column to the right, row down.
  double column_of(double x_m) const { return (x_m - min_x_m) / pixel_size_m; }
  double row_of(double y_m) const { return (max_y_m - y_m) / pixel_size_m; }
  /// The map point at the centre of a pixel.
  double x_of(int column) const { return min_x_m + (column + 0.5) * pixel_size_m; }
  double y_of(int row) const { return max_y_m - (row + 0.5) * pixel_size_m; }
};

}  // namespace featsense::viewer_export
