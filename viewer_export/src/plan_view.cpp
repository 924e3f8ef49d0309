#include "featsense/viewer_export/plan_view.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "internal/cut_height_field.hpp"
#include "internal/plan_frame.hpp"
#include "internal/plan_overlay.hpp"
#include "internal/plan_shading.hpp"
#include "internal/plan_surface.hpp"
#include "internal/png_encoder.hpp"

namespace featsense::viewer_export {
namespace {

constexpr double kFinestPixelM = 0.01;
constexpr double kPaddingShare = 0.04;  // of the map's extent, on each side: walls off the edge
constexpr int kMinShortSidePx = 320;    // room for the legend beside a long, narrow map

std::vector<Eigen::Vector3d> finite_positions(const std::vector<PlanPath>& paths) {
  std::vector<Eigen::Vector3d> positions;
  for (const PlanPath& path : paths) {
    for (const Eigen::Vector3d& p : path.positions_m)
      if (p.allFinite()) positions.push_back(p);
  }
  return positions;
}

/// The mesh and the paths with a margin around them, in pixels of the settings' size (finer
/// for small maps, coarser for large ones).
PlanFrame frame_around(const mesh::TriangleMesh& mesh,
                       const std::vector<Eigen::Vector3d>& positions,
                       const PlanViewSettings& settings) {
  Eigen::AlignedBox2d box;
  for (const Eigen::Vector3f& v : mesh.vertices) box.extend(v.head<2>().cast<double>());
  for (const Eigen::Vector3d& p : positions) box.extend(p.head<2>());
  const double extent = std::max(box.sizes().maxCoeff(), 1e-3);
  const Eigen::Vector2d padded = box.sizes().array() + 2.0 * kPaddingShare * extent;
  const double padded_extent = padded.maxCoeff();
  const int max_side = std::max(settings.max_side_px, 1);
  const int min_side = std::clamp(settings.min_side_px, 1, max_side);
  double pixel = std::min(settings.pixel_size_m, padded_extent / min_side);
  pixel = std::max({pixel, kFinestPixelM, padded_extent / max_side});

  PlanFrame frame;
  frame.pixel_size_m = pixel;
  frame.width_px = std::clamp(static_cast<int>(std::ceil(padded.x() / pixel)), 1, max_side);
  frame.height_px = std::clamp(static_cast<int>(std::ceil(padded.y() / pixel)), 1, max_side);
  frame.width_px = std::max(frame.width_px, std::min(kMinShortSidePx, max_side));
  // Centred: the margins share what the padding and the minimum side added.
  const Eigen::Vector2d centre = box.center();
  frame.min_x_m = centre.x() - 0.5 * frame.width_px * pixel;
  frame.max_y_m = centre.y() + 0.5 * frame.height_px * pixel;
  return frame;
}

CutHeightField choose_cut(const mesh::TriangleMesh& mesh,
                          const std::vector<Eigen::Vector3d>& positions,
                          const PlanViewSettings& settings, const PlanFrame& frame) {
  if (settings.cut_height_m) {
    char rule[64];
    std::snprintf(rule, sizeof(rule), "fixed at z = %.2f m", *settings.cut_height_m);
    return CutHeightField::fixed(*settings.cut_height_m, rule);
  }
  if (!positions.empty()) {
    return CutHeightField::along_paths(positions, settings.cut_margin_m, settings.cut_radius_m,
                                       frame);
  }
  return CutHeightField::from_floors_and_ceilings(mesh);
}

/// The legend's line on the cut: its heights, in few words.
std::string cut_legend(const CutHeightField& cut) {
  if (!std::isfinite(cut.highest_m())) return "nothing cut away";
  char text[96];
  if (cut.highest_m() - cut.lowest_m() < 0.005) {
    std::snprintf(text, sizeof(text), "cut at z %.2f m", cut.lowest_m());
  } else {
    std::snprintf(text, sizeof(text), "cut at z %.2f to %.2f m", cut.lowest_m(), cut.highest_m());
  }
  return text;
}

}  // namespace

double plan_grid_spacing_m(double extent_m) {
  if (!(extent_m > 0.0) || !std::isfinite(extent_m)) return 1.0;
  const double wanted = extent_m / 10.0;
  double decade = std::pow(10.0, std::floor(std::log10(wanted)));
  for (;; decade *= 10.0) {
    for (const double step : {1.0, 2.0, 5.0}) {
      // A hair of tolerance, so that 100 m across gets 10 m and not 20 m.
      if (step * decade >= wanted * (1.0 - 1e-9)) return step * decade;
    }
  }
}

PlanImage render_plan_view(const mesh::TriangleMesh& mesh, const std::vector<PlanPath>& paths,
                           const PlanViewSettings& settings, const PlanVertexColours* colours) {
  if (mesh.triangles.empty()) throw mesh::MeshError("a plan view needs triangles");
  mesh::validate(mesh, "the plan view's mesh");
  if (colours != nullptr && (colours->rgb.size() != mesh.vertices.size() || !colours->ramp)) {
    throw mesh::MeshError("a plan view's colours need one per vertex and a ramp");
  }
  const std::vector<Eigen::Vector3d> positions = finite_positions(paths);
  PlanFrame frame = frame_around(mesh, positions, settings);
  const PlanStyle style = plan_style(std::max(frame.width_px, frame.height_px));
  const double map_extent_m = std::max(frame.width_px, frame.height_px) * frame.pixel_size_m;
  // Bands above and below the map for the legend and the scale bar.
  const int top_band = legend_height_px(style, paths.size()) + 2 * style.gap;
  const int bottom_band = scale_bar_height_px(style) + 2 * style.gap;
  frame.max_y_m += top_band * frame.pixel_size_m;
  frame.height_px += top_band + bottom_band;
  const CutHeightField cut = choose_cut(mesh, positions, settings, frame);
  PlanSurface surface = rasterize_below_cut(mesh, frame, cut);
  const HeightRange heights = colour_range(surface);

  PlanImage image;
  PlanLegend legend{cut_legend(cut), height_ramp_legend(heights)};
  if (colours != nullptr) {
    image.rgba = shade_plan_by_vertex(surface, frame, mesh, colours->rgb);
    legend.ramp = {colours->low, colours->high, colours->ramp};
  } else {
    image.rgba = shade_plan(surface, frame, heights);
  }
  const double spacing = plan_grid_spacing_m(map_extent_m);
  draw_grid(image.rgba, frame, spacing);
  draw_paths(image.rgba, frame, style, paths);
  draw_scale_bar(image.rgba, frame, style, spacing);
  draw_legend(image.rgba, frame, style, paths, legend);
  image.surface_height_m = std::move(surface.height_m);

  PlanView& view = image.view;
  view.width_px = frame.width_px;
  view.height_px = frame.height_px;
  view.pixel_size_m = frame.pixel_size_m;
  view.min_x_m = frame.min_x_m;
  view.max_y_m = frame.max_y_m;
  view.cut_rule = cut.rule();
  view.cut_low_m = cut.lowest_m();
  view.cut_high_m = cut.highest_m();
  view.grid_spacing_m = spacing;
  view.low_z_m = heights.low_m;
  view.high_z_m = heights.high_m;
  return image;
}

PlanView write_plan_view_png(const mesh::TriangleMesh& mesh, const std::vector<PlanPath>& paths,
                             const std::string& path, const PlanViewSettings& settings,
                             const PlanVertexColours* colours) {
  const PlanImage image = render_plan_view(mesh, paths, settings, colours);
  write_rgba_png(path, image.rgba, image.view.width_px, image.view.height_px);
  return image.view;
}

}  // namespace featsense::viewer_export
