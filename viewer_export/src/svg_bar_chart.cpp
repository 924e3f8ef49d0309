#include "featsense/viewer_export/svg_bar_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "featsense/viewer_export/html_text.hpp"

namespace featsense::viewer_export {
namespace {

/// Room right of the longest bar for its value's text.
constexpr int kValueWidthPx = 90;
constexpr int kTitleHeightPx = 24;
constexpr int kRowGapPx = 6;

/// A coordinate with one decimal, as SVG attributes take it.
std::string px(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f", value);
  return text;
}

}  // namespace

std::string svg_bar_chart(const BarChart& chart) {
  const int row = chart.bar_height_px + kRowGapPx;
  const int height = kTitleHeightPx + static_cast<int>(chart.bars.size()) * row + kRowGapPx;
  const int plot_width = std::max(10, chart.width_px - chart.label_width_px - kValueWidthPx);
  double largest = 0.0;
  for (const BarChartBar& bar : chart.bars)
    if (std::isfinite(bar.value)) largest = std::max(largest, bar.value);

  // Inline in HTML: no xmlns needed, so that the page names no address at all.
  std::string svg = "<svg class=\"chart\" width=\"" + std::to_string(chart.width_px) +
                    "\" height=\"" + std::to_string(height) + "\" viewBox=\"0 0 " +
                    std::to_string(chart.width_px) + " " + std::to_string(height) +
                    "\" role=\"img\">\n";
  svg += "<title>" + html_escape(chart.title) + "</title>\n";
  svg += "<text class=\"chart-title\" x=\"0\" y=\"16\">" + html_escape(chart.title) + "</text>\n";
  for (size_t i = 0; i < chart.bars.size(); ++i) {
    const BarChartBar& bar = chart.bars[i];
    const double top = kTitleHeightPx + static_cast<double>(i) * row;
    const double fraction =
        largest > 0.0 && std::isfinite(bar.value) ? std::max(0.0, bar.value) / largest : 0.0;
    const double width = fraction * plot_width;
    const double middle = top + chart.bar_height_px * 0.5;
    svg += "<text class=\"bar-label\" x=\"" + px(chart.label_width_px - 6.0) + "\" y=\"" +
           px(middle) + "\" text-anchor=\"end\" dominant-baseline=\"middle\">" +
           html_escape(bar.label) + "</text>\n";
    svg += "<rect class=\"bar\" x=\"" + px(chart.label_width_px) + "\" y=\"" + px(top) +
           "\" width=\"" + px(width) + "\" height=\"" + px(chart.bar_height_px) + "\"/>\n";
    svg += "<text class=\"bar-value\" x=\"" + px(chart.label_width_px + width + 6.0) + "\" y=\"" +
           px(middle) + "\" dominant-baseline=\"middle\">" +
           html_escape(number_text(bar.value) + " " + chart.unit) + "</text>\n";
  }
  svg += "</svg>\n";
  return svg;
}

}  // namespace featsense::viewer_export
