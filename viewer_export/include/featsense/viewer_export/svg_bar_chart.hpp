#pragma once
// A horizontal bar chart as inline SVG: report.html's timing charts, drawn without scripts
// or fonts from anywhere (the browser's own sans-serif).

#include <string>
#include <vector>

namespace featsense::viewer_export {

struct BarChartBar {
  std::string label;
  double value = 0.0;  ///< in the chart's unit; negative values draw as empty bars
};

struct BarChart {
  std::string title;
  std::string unit;  ///< written after each value ("ms", "s")
  std::vector<BarChartBar> bars;
  int width_px = 640;
  int label_width_px = 170;  ///< the column of the bars' labels
  int bar_height_px = 18;
};

/// The chart as an `<svg>` element: one `<rect class="bar">` per bar, its width proportional
/// to its value (the largest spans the plot), the label left of it and the value right of
/// it; every text escaped.
std::string svg_bar_chart(const BarChart& chart);

}  // namespace featsense::viewer_export
