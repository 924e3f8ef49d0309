// The time-series plot (trajectory_error.png): the curves' pixels where a known series puts
// them, a gap where a value is missing, markers on the time axis, round axis ends.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/viewer_export/time_series_plot.hpp"

namespace featsense::viewer_export {
namespace {

constexpr std::array<uint8_t, 3> kRed = {215, 25, 28};
constexpr std::array<uint8_t, 3> kBlue = {35, 100, 220};

/// Whether a pixel within one of (column, row) has (about) `colour`.
bool curve_near(const TimeSeriesImage& image, double column, double row,
                const std::array<uint8_t, 3>& colour) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = static_cast<int>(std::lround(column)) + dx;
      const int y = static_cast<int>(std::lround(row)) + dy;
      if (x < 0 || y < 0 || x >= image.width_px || y >= image.height_px) continue;
      const uint8_t* p = &image.rgba[4 * (static_cast<size_t>(y) * image.width_px + x)];
      if (std::abs(p[0] - colour[0]) < 30 && std::abs(p[1] - colour[1]) < 30 &&
          std::abs(p[2] - colour[2]) < 30)
        return true;
    }
  }
  return false;
}

/// A ramp 0..1 m over 10 s above a constant 2 deg, the loop at 5 s.
TimeSeriesPlot ramp_plot() {
  TimeSeriesPlot plot;
  plot.title = "error";
  for (int i = 0; i <= 100; ++i) plot.times_s.push_back(0.1 * i);
  plot.panels.push_back({"translation error (m)", {}, kRed});
  plot.panels.push_back({"rotation error (deg)", {}, kBlue});
  for (const double t : plot.times_s) {
    plot.panels[0].values.push_back(0.1 * t);
    plot.panels[1].values.push_back(2.0);
  }
  plot.marker_times_s = {5.0};
  plot.marker_label = "loop closed";
  return plot;
}

TEST(TimeSeriesPlot, DrawsAKnownSeriesWhereItsValuesAre) {
  const TimeSeriesImage image = render_time_series(ramp_plot());
  ASSERT_EQ(image.areas.size(), 2u);
  ASSERT_EQ(image.rgba.size(), static_cast<size_t>(image.width_px) * image.height_px * 4);
  const PlotArea& top = image.areas[0];
  const PlotArea& bottom = image.areas[1];
  EXPECT_LT(top.top_px + top.height_px, bottom.top_px);  // stacked, one above the other
  // Round ends: time 0..10 s, the ramp 0..1 m, the constant from 0.
  EXPECT_DOUBLE_EQ(top.time_low_s, 0.0);
  EXPECT_DOUBLE_EQ(top.time_high_s, 10.0);
  EXPECT_DOUBLE_EQ(top.value_low, 0.0);
  EXPECT_NEAR(top.value_high, 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(bottom.value_low, 0.0);
  EXPECT_NEAR(bottom.value_high, 2.0, 1e-9);

  for (const double t : {0.5, 2.0, 3.3, 5.0, 7.5, 9.5}) {
    EXPECT_TRUE(curve_near(image, top.column_of(t), top.row_of(0.1 * t), kRed)) << t;
    // A line, not a band: 0.15 m off the value is off the curve.
    const double off = 0.1 * t + (t < 5.0 ? 0.15 : -0.15);
    EXPECT_FALSE(curve_near(image, top.column_of(t), top.row_of(off), kRed)) << t;
    EXPECT_TRUE(curve_near(image, bottom.column_of(t), bottom.row_of(2.0), kBlue)) << t;
    EXPECT_FALSE(curve_near(image, bottom.column_of(t), bottom.row_of(1.0), kBlue)) << t;
  }
  // Each curve in its own panel only.
  EXPECT_FALSE(curve_near(image, top.column_of(5.0), top.row_of(0.5), kBlue));
}

TEST(TimeSeriesPlot, MarksEventsOnTheTimeAxis) {
  const TimeSeriesImage image = render_time_series(ramp_plot());
  const std::array<uint8_t, 3> orange = {240, 140, 0};
  for (const PlotArea& area : image.areas) {
    const int bottom = area.top_px + area.height_px - 1;
    EXPECT_TRUE(curve_near(image, area.column_of(5.0), bottom + 2, orange));
    EXPECT_FALSE(curve_near(image, area.column_of(2.0), bottom + 2, orange));
  }
}

TEST(TimeSeriesPlot, LeavesAGapWhereAValueIsMissing) {
  TimeSeriesPlot plot = ramp_plot();
  for (size_t i = 40; i <= 60; ++i)
    plot.panels[0].values[i] = std::numeric_limits<double>::quiet_NaN();
  const TimeSeriesImage image = render_time_series(plot);
  const PlotArea& top = image.areas[0];
  EXPECT_TRUE(curve_near(image, top.column_of(3.0), top.row_of(0.3), kRed));
  EXPECT_FALSE(curve_near(image, top.column_of(5.0), top.row_of(0.5), kRed));
  EXPECT_TRUE(curve_near(image, top.column_of(7.0), top.row_of(0.7), kRed));
}

TEST(TimeSeriesPlot, WritesAPng) {
  const std::filesystem::path file = test::scratch_dir("time_series_plot") / "plot.png";
  const TimeSeriesImage image = write_time_series_png(ramp_plot(), file.string());
  ASSERT_TRUE(std::filesystem::is_regular_file(file));
  EXPECT_GT(std::filesystem::file_size(file), 1000u);
  EXPECT_EQ(image.width_px, 1000);
}

}  // namespace
}  // namespace featsense::viewer_export
