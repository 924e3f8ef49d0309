#pragma once
// Panels of values over time stacked above one time axis, as a PNG (trajectory_error.png):
// tick labels, units and a title in the plan view's text (OpenCV's Hershey font), markers
// for events on the time axis.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace featsense::viewer_export {

struct TimeSeriesPanel {
  std::string label;           ///< the value axis, with its unit: "translation error (m)"
  std::vector<double> values;  ///< one per time of the plot; non-finite ones leave a gap
  std::array<uint8_t, 3> colour = {215, 25, 28};  ///< RGB of the curve
};

struct TimeSeriesPlot {
  std::string title;
  std::string time_label = "time (s)";
  std::vector<double> times_s;  ///< increasing
  std::vector<TimeSeriesPanel> panels;
  std::vector<double> marker_times_s;  ///< events drawn as small triangles on the time axis
  std::string marker_label;            ///< what the markers stand for, in the title line
  int width_px = 1000;
  int panel_height_px = 240;  ///< the plot area of one panel
};

/// Where a panel's plot area lies in the picture and which values its edges stand for.
struct PlotArea {
  int left_px = 0;
  int top_px = 0;
  int width_px = 0;
  int height_px = 0;
  double time_low_s = 0.0;
  double time_high_s = 1.0;
  double value_low = 0.0;
  double value_high = 1.0;

  /// Continuous pixel coordinates: column to the right, row down.
  double column_of(double time_s) const {
    return left_px + (time_s - time_low_s) / (time_high_s - time_low_s) * (width_px - 1);
  }
  double row_of(double value) const {
    return top_px + (value_high - value) / (value_high - value_low) * (height_px - 1);
  }
};

struct TimeSeriesImage {
  std::vector<uint8_t> rgba;  ///< rows from the top, 4 bytes a pixel
  int width_px = 0;
  int height_px = 0;
  std::vector<PlotArea> areas;  ///< one per panel, top to bottom
};

/// Draws the plot. Each panel's value axis starts at 0 (or below, for negative values) and
/// ends at a round number above its largest value.
TimeSeriesImage render_time_series(const TimeSeriesPlot& plot);

/// Draws the plot and writes it as a PNG. Throws std::runtime_error when it cannot.
TimeSeriesImage write_time_series_png(const TimeSeriesPlot& plot, const std::string& path);

}  // namespace featsense::viewer_export
