#pragma once
/// The plan view of a map (topdown.png): the mesh seen from straight above with everything
/// above a cut height taken away (ceilings, roofs of car parks), so that the place shows as a
/// floor plan: floors coloured by height and hill-shaded, walls and the sides of objects as
/// dark lines, the sensor's path (and the true one, where known) on top, a metric grid, a
/// scale bar and a legend.

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::viewer_export {

/// A path drawn on the plan: the positions of the sensor, map frame, metres. A non-finite
/// position is a gap: the line stops there and goes on at the next position.
struct PlanPath {
  /// estimate: red; truth: blue, wider and drawn below; uncertain: amber, an estimate held
  /// with less confidence (a localizer's poses on odometry alone), drawn below the estimate.
  enum class Kind { kEstimate, kTruth, kUncertain };
  Kind kind = Kind::kEstimate;
  std::string label;  ///< the legend's text
  std::vector<Eigen::Vector3d> positions_m;
};

struct PlanViewSettings {
  double pixel_size_m = 0.05;  ///< the finest pixel of a map of ordinary size
  int min_side_px = 800;       ///< smaller maps get smaller pixels (down to 1 cm), for the text
  int max_side_px = 4096;      ///< larger maps get bigger pixels
  /// A fixed cut (map frame z, metres) for the whole map; nullopt: it follows the paths.
  std::optional<double> cut_height_m;
  /// The cut that follows the paths lies this far above the highest sensor position within
  /// cut_radius_m of a pixel (else that of the nearest position). Small on purpose: a walking
  /// sensor (1.5-1.8 m) sees doors of 2.0-2.2 m, which should stay gaps in the walls, and a
  /// car's roof sensor (1.9 m) in a car park has its ceiling at 2.2-2.5 m.
  double cut_margin_m = 0.3;
  /// Horizontal radius within which the path sets the cut: small enough that the cut follows
  /// a ramp (10 % over 4 m is 0.4 m), large enough to cover a room from a path through it.
  double cut_radius_m = 4.0;
};

/// Colours for the plan's surfaces in place of their heights: one per vertex of the mesh (a
/// surface takes the mean of its triangle's), with the ramp the legend shows for them.
struct PlanVertexColours {
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> rgb;         ///< per vertex (as MeshAttributes::colors)
  std::string low;                                       ///< the legend's text before the ramp
  std::string high;                                      ///< and after it
  std::function<std::array<uint8_t, 3>(double t)> ramp;  ///< t from 0 (low) to 1 (high)
};

/// What the plan shows and how it was drawn, for reports.
struct PlanView {
  int width_px = 0;
  int height_px = 0;
  double pixel_size_m = 0.0;
  double min_x_m = 0.0;         ///< the left edge of the image, map frame
  double max_y_m = 0.0;         ///< the top edge (north up: +y is up in the image)
  std::string cut_rule;         ///< how the cut height was chosen, in words
  double cut_low_m = 0.0;       ///< the lowest cut used (+inf: nothing was cut away)
  double cut_high_m = 0.0;      ///< the highest cut used
  double grid_spacing_m = 0.0;  ///< between grid lines, also the scale bar's length
  double low_z_m = 0.0;         ///< the height of the first colour of the ramp
  double high_z_m = 0.0;        ///< the height of the last colour
};

/// The plan as pixels: RGBA rows from the top (north) down, and the height of the surface seen
/// in each pixel (NaN where there is none).
struct PlanImage {
  PlanView view;
  std::vector<unsigned char> rgba;
  std::vector<float> surface_height_m;
};

/// Draws the plan of `mesh` with `paths` (any number; empty: the cut comes from the mesh's
/// floors and ceilings alone), its surfaces coloured by height, or by `colours` where given
/// (the same cut, paths, grid and scale bar). Throws mesh::MeshError for a mesh without
/// triangles, or colours that are not one per vertex.
PlanImage render_plan_view(const mesh::TriangleMesh& mesh, const std::vector<PlanPath>& paths,
                           const PlanViewSettings& settings = {},
                           const PlanVertexColours* colours = nullptr);

/// render_plan_view, written to `path` as a PNG. Throws mesh::MeshError for a mesh without
/// triangles, std::runtime_error when the file cannot be written.
PlanView write_plan_view_png(const mesh::TriangleMesh& mesh, const std::vector<PlanPath>& paths,
                             const std::string& path, const PlanViewSettings& settings = {},
                             const PlanVertexColours* colours = nullptr);

/// The grid's spacing for a map `extent_m` across: the smallest of 1, 2, 5 x 10^k m that
/// leaves at most ten cells across (37 m: 5 m, 400 m: 50 m).
double plan_grid_spacing_m(double extent_m);

}  // namespace featsense::viewer_export
