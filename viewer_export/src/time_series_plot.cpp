#include "featsense/viewer_export/time_series_plot.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "internal/plot_ticks.hpp"
#include "internal/png_encoder.hpp"

namespace featsense::viewer_export {
namespace {

// Channels are RGBA, as the PNG stores them (the plan view's conventions).
const cv::Scalar kInk(20, 20, 20, 255);
const cv::Scalar kGrid(225, 225, 225, 255);
const cv::Scalar kAxis(120, 120, 120, 255);
const cv::Scalar kMarker(240, 140, 0, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.45;
constexpr double kTitleScale = 0.6;
constexpr int kLeftPx = 72;  // the value ticks' labels
constexpr int kRightPx = 24;
constexpr int kTitlePx = 40;     // the title line
constexpr int kLabelPx = 26;     // a panel's label above it
constexpr int kPanelGapPx = 34;  // the time ticks' labels under a panel
constexpr int kBottomPx = 44;    // the time ticks' labels and the time axis' label
constexpr int kMarkerPx = 6;     // half the width of an event's triangle

cv::Size text_size(const std::string& text, double scale) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, 1, &baseline);
}

void put_text(cv::Mat& image, const std::string& text, int x, int baseline_y,
              double scale = kFontScale) {
  cv::putText(image, text, cv::Point(x, baseline_y), kFont, scale, kInk, 1, cv::LINE_AA);
}

void draw_marker(cv::Mat& image, int column, int bottom_row) {
  const std::vector<cv::Point> triangle = {{column, bottom_row - kMarkerPx},
                                           {column - kMarkerPx, bottom_row + kMarkerPx},
                                           {column + kMarkerPx, bottom_row + kMarkerPx}};
  cv::fillConvexPoly(image, triangle, kMarker, cv::LINE_AA);
}

/// The value range of a panel: from 0 (or its lowest value, when negative) to its highest.
AxisTicks value_ticks(const std::vector<double>& values) {
  double low = 0.0;
  double high = 0.0;
  for (const double v : values) {
    if (!std::isfinite(v)) continue;
    low = std::min(low, v);
    high = std::max(high, v);
  }
  return axis_ticks(low, high, 5);
}

void draw_panel(cv::Mat& image, const TimeSeriesPlot& plot, const TimeSeriesPanel& panel,
                const PlotArea& area, const AxisTicks& times, const AxisTicks& values) {
  const int right = area.left_px + area.width_px - 1;
  const int bottom = area.top_px + area.height_px - 1;
  put_text(image, panel.label, area.left_px, area.top_px - 8);
  for (const double t : times.values) {
    const int column = static_cast<int>(std::lround(area.column_of(t)));
    cv::line(image, {column, area.top_px}, {column, bottom}, kGrid);
    cv::line(image, {column, bottom}, {column, bottom + 4}, kAxis);
    const std::string text = tick_text(t, times.step);
    put_text(image, text, column - text_size(text, kFontScale).width / 2, bottom + 20);
  }
  for (const double v : values.values) {
    const int row = static_cast<int>(std::lround(area.row_of(v)));
    cv::line(image, {area.left_px, row}, {right, row}, kGrid);
    cv::line(image, {area.left_px - 4, row}, {area.left_px, row}, kAxis);
    const std::string text = tick_text(v, values.step);
    const cv::Size size = text_size(text, kFontScale);
    put_text(image, text, area.left_px - 8 - size.width, row + size.height / 2);
  }
  cv::rectangle(image, cv::Rect(area.left_px, area.top_px, area.width_px, area.height_px), kAxis);

  // The curve, in runs between gaps; sub-pixel positions in OpenCV's fixed point.
  constexpr int kShift = 4;
  constexpr double kScale = 1 << kShift;
  const cv::Scalar colour(panel.colour[0], panel.colour[1], panel.colour[2], 255);
  std::vector<cv::Point> run;
  const auto flush = [&] {
    if (run.size() == 1)
      cv::circle(image, run.front(), 2 << kShift, colour, cv::FILLED, cv::LINE_AA, kShift);
    if (run.size() > 1) cv::polylines(image, run, false, colour, 2, cv::LINE_AA, kShift);
    run.clear();
  };
  const size_t n = std::min(plot.times_s.size(), panel.values.size());
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(panel.values[i]) || !std::isfinite(plot.times_s[i])) {
      flush();
      continue;
    }
    run.emplace_back(static_cast<int>(std::lround(area.column_of(plot.times_s[i]) * kScale)),
                     static_cast<int>(std::lround(area.row_of(panel.values[i]) * kScale)));
  }
  flush();
  for (const double t : plot.marker_times_s) {
    if (t < area.time_low_s || t > area.time_high_s) continue;
    draw_marker(image, static_cast<int>(std::lround(area.column_of(t))), bottom);
  }
}

}  // namespace

TimeSeriesImage render_time_series(const TimeSeriesPlot& plot) {
  TimeSeriesImage image;
  const int panels = static_cast<int>(plot.panels.size());
  image.width_px = std::max(plot.width_px, kLeftPx + kRightPx + 50);
  image.height_px = kTitlePx + panels * (kLabelPx + plot.panel_height_px) +
                    std::max(0, panels - 1) * kPanelGapPx + kBottomPx;
  image.rgba.assign(static_cast<size_t>(image.width_px) * image.height_px * 4, 255);
  cv::Mat mat(image.height_px, image.width_px, CV_8UC4, image.rgba.data());

  double first = 0.0;
  double last = 0.0;
  if (!plot.times_s.empty()) {
    first = plot.times_s.front();
    last = plot.times_s.back();
  }
  const AxisTicks times = axis_ticks(first, last, 10);

  put_text(mat, plot.title, kLeftPx, 26, kTitleScale);
  if (!plot.marker_times_s.empty() && !plot.marker_label.empty()) {
    const int width = text_size(plot.marker_label, kFontScale).width;
    const int x = image.width_px - kRightPx - width;
    draw_marker(mat, x - 2 * kMarkerPx, 20);
    put_text(mat, plot.marker_label, x, 26);
  }
  int top = kTitlePx;
  for (const TimeSeriesPanel& panel : plot.panels) {
    const AxisTicks values = value_ticks(panel.values);
    PlotArea area;
    area.left_px = kLeftPx;
    area.top_px = top + kLabelPx;
    area.width_px = image.width_px - kLeftPx - kRightPx;
    area.height_px = plot.panel_height_px;
    area.time_low_s = times.low;
    area.time_high_s = times.high;
    area.value_low = values.low;
    area.value_high = values.high;
    draw_panel(mat, plot, panel, area, times, values);
    image.areas.push_back(area);
    top = area.top_px + area.height_px + kPanelGapPx;
  }
  const cv::Size size = text_size(plot.time_label, kFontScale);
  put_text(mat, plot.time_label, kLeftPx + (image.width_px - kLeftPx - kRightPx - size.width) / 2,
           image.height_px - 6);
  return image;
}

TimeSeriesImage write_time_series_png(const TimeSeriesPlot& plot, const std::string& path) {
  TimeSeriesImage image = render_time_series(plot);
  write_rgba_png(path, image.rgba, image.width_px, image.height_px);
  return image;
}

}  // namespace featsense::viewer_export
