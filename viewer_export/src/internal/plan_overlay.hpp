#pragma once
// What is drawn over the plan's surfaces: the metric grid, the paths, the scale bar and the
// legend (OpenCV's imgproc, which the program links for the front end already).

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "featsense/viewer_export/plan_view.hpp"
#include "internal/plan_frame.hpp"
#include "internal/plan_shading.hpp"

namespace featsense::viewer_export {

/// Text, lines and margins grow with the image, so that they read at the size it is shown.
struct PlanStyle {
  double font_scale = 0.5;
  int thickness = 1;     ///< of the text's strokes, pixels
  int text_height = 10;  ///< pixels
  int gap = 5;           ///< margins and spacing, pixels
  int path_width = 2;    ///< pixels
};

/// The style for a map `side_px` pixels on its longer side.
PlanStyle plan_style(int side_px);

/// The height of the legend's box (paths, the cut, the ramp) and of the scale bar's: the
/// plan leaves bands of these above and below the map, so that they hide none of it.
int legend_height_px(const PlanStyle& style, size_t paths);
int scale_bar_height_px(const PlanStyle& style);

/// The legend's colour ramp: what the surfaces' colours mean.
struct PlanRampLegend {
  std::string low;   ///< the text before the ramp, at t = 0 ("z 0.0 m")
  std::string high;  ///< the text after it, at t = 1
  std::function<std::array<uint8_t, 3>(double t)> colour;
};

/// The height ramp between the two heights of `colours`.
PlanRampLegend height_ramp_legend(const HeightRange& colours);

struct PlanLegend {
  std::string cut;  ///< one line on where the plan was cut
  PlanRampLegend ramp;
};

/// Lines every `spacing_m` (map frame multiples of it), blended in grey.
void draw_grid(std::vector<uint8_t>& rgba, const PlanFrame& frame, double spacing_m);

/// The paths (truths first, estimates over them), each with a dot where it starts.
void draw_paths(std::vector<uint8_t>& rgba, const PlanFrame& frame, const PlanStyle& style,
                const std::vector<PlanPath>& paths);

/// A bar `length_m` long with its length written above it, bottom left.
void draw_scale_bar(std::vector<uint8_t>& rgba, const PlanFrame& frame, const PlanStyle& style,
                    double length_m);

/// Top left: a line per path in its colour and label, the cut, the height ramp.
void draw_legend(std::vector<uint8_t>& rgba, const PlanFrame& frame, const PlanStyle& style,
                 const std::vector<PlanPath>& paths, const PlanLegend& legend);

/// "50 cm", "5 m", "2 km".
std::string length_text(double metres);

}  // namespace featsense::viewer_export
