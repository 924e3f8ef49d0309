#include "internal/cut_height_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>

#include "internal/horizontal_levels.hpp"

namespace featsense::viewer_export {
namespace {

constexpr double kCutAboveFloorM = 1.5;  // where architects cut a floor plan: below lintels

std::string metres(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f m", value);
  return text;
}

}  // namespace

CutHeightField CutHeightField::fixed(double height_m, std::string rule) {
  CutHeightField field;
  field.cells_ = {height_m};
  field.lowest_m_ = field.highest_m_ = height_m;
  field.rule_ = std::move(rule);
  return field;
}

CutHeightField CutHeightField::along_paths(const std::vector<Eigen::Vector3d>& positions_m,
                                           double margin_m, double radius_m,
                                           const PlanFrame& frame) {
  CutHeightField field;
  // Four cells across the radius keep the cut's steps small; never finer than a pixel.
  field.cell_m_ = std::max(radius_m / 4.0, frame.pixel_size_m);
  field.min_x_m_ = frame.min_x_m;
  field.max_y_m_ = frame.max_y_m;
  field.columns_ =
      std::max(1, static_cast<int>(std::ceil(frame.width_px * frame.pixel_size_m / field.cell_m_)));
  field.rows_ = std::max(
      1, static_cast<int>(std::ceil(frame.height_px * frame.pixel_size_m / field.cell_m_)));
  const size_t cells = static_cast<size_t>(field.columns_) * static_cast<size_t>(field.rows_);
  field.cells_.assign(cells, std::numeric_limits<double>::quiet_NaN());
  const auto index = [&](int column, int row) {
    return static_cast<size_t>(row) * static_cast<size_t>(field.columns_) +
           static_cast<size_t>(column);
  };

  // Each position raises the cut over the cells whose centres lie within the radius.
  std::deque<std::pair<int, int>> reached;
  const int reach = static_cast<int>(std::ceil(radius_m / field.cell_m_));
  for (const Eigen::Vector3d& p : positions_m) {
    const double height = p.z() + margin_m;
    const int c0 = static_cast<int>(std::floor((p.x() - field.min_x_m_) / field.cell_m_));
    const int r0 = static_cast<int>(std::floor((field.max_y_m_ - p.y()) / field.cell_m_));
    for (int r = std::max(0, r0 - reach); r <= std::min(field.rows_ - 1, r0 + reach); ++r) {
      for (int c = std::max(0, c0 - reach); c <= std::min(field.columns_ - 1, c0 + reach); ++c) {
        const double dx = field.min_x_m_ + (c + 0.5) * field.cell_m_ - p.x();
        const double dy = field.max_y_m_ - (r + 0.5) * field.cell_m_ - p.y();
        if (dx * dx + dy * dy > radius_m * radius_m) continue;
        double& cell = field.cells_[index(c, r)];
        if (std::isnan(cell)) reached.emplace_back(c, r);
        if (!(cell >= height)) cell = height;
      }
    }
  }
  if (reached.empty()) {
    // No position inside the plan (a path far from the mesh): the highest one for all.
    double highest = -std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& p : positions_m) highest = std::max(highest, p.z() + margin_m);
    return fixed(highest, metres(margin_m) + " above the highest sensor position");
  }
  // Cells far from the path take the cut of the nearest cell that has one (a breadth-first
  // flood, 8-connected: near enough to the nearest position for a cut).
  while (!reached.empty()) {
    const auto [c, r] = reached.front();
    reached.pop_front();
    const double value = field.cells_[index(c, r)];
    for (int dr = -1; dr <= 1; ++dr) {
      for (int dc = -1; dc <= 1; ++dc) {
        const int nc = c + dc;
        const int nr = r + dr;
        if (nc < 0 || nr < 0 || nc >= field.columns_ || nr >= field.rows_) continue;
        double& next = field.cells_[index(nc, nr)];
        if (!std::isnan(next)) continue;
        next = value;
        reached.emplace_back(nc, nr);
      }
    }
  }
  const auto [low, high] = std::minmax_element(field.cells_.begin(), field.cells_.end());
  field.lowest_m_ = *low;
  field.highest_m_ = *high;
  field.rule_ = metres(margin_m) + " above the highest sensor position within " + metres(radius_m) +
                " (else the nearest)";
  return field;
}

CutHeightField CutHeightField::from_floors_and_ceilings(const mesh::TriangleMesh& mesh) {
  const HorizontalLevels levels = find_horizontal_levels(mesh);
  if (!levels.floor_m || !levels.ceiling_m) {
    return fixed(std::numeric_limits<double>::infinity(),
                 "no cut: no path given and no ceiling found");
  }
  const double above_floor = std::min(kCutAboveFloorM, 0.5 * (*levels.ceiling_m - *levels.floor_m));
  return fixed(*levels.floor_m + above_floor,
               "no path given: " + metres(above_floor) + " above the main floor at " +
                   metres(*levels.floor_m) + " (ceiling at " + metres(*levels.ceiling_m) + ")");
}

double CutHeightField::at(double x_m, double y_m) const {
  if (cells_.size() == 1) return cells_.front();
  // Bilinear between the centres of the four nearest cells, clamped at the edges.
  const double u = std::clamp((x_m - min_x_m_) / cell_m_ - 0.5, 0.0, columns_ - 1.0);
  const double v = std::clamp((max_y_m_ - y_m) / cell_m_ - 0.5, 0.0, rows_ - 1.0);
  const int c = std::min(static_cast<int>(u), columns_ - 2 < 0 ? 0 : columns_ - 2);
  const int r = std::min(static_cast<int>(v), rows_ - 2 < 0 ? 0 : rows_ - 2);
  const int c1 = std::min(c + 1, columns_ - 1);
  const int r1 = std::min(r + 1, rows_ - 1);
  const double fu = std::clamp(u - c, 0.0, 1.0);
  const double fv = std::clamp(v - r, 0.0, 1.0);
  const auto cell = [&](int column, int row) {
    return cells_[static_cast<size_t>(row) * static_cast<size_t>(columns_) +
                  static_cast<size_t>(column)];
  };
  const double top = cell(c, r) + fu * (cell(c1, r) - cell(c, r));
  const double bottom = cell(c, r1) + fu * (cell(c1, r1) - cell(c, r1));
  return top + fv * (bottom - top);
}

}  // namespace featsense::viewer_export
