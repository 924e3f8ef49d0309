#include "internal/plan_overlay.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace featsense::viewer_export {
namespace {

// Channels are RGBA, as the PNG stores them.
const cv::Scalar kEstimateColour(215, 25, 28, 255);
const cv::Scalar kTruthColour(35, 100, 220, 255);
const cv::Scalar kUncertainColour(245, 160, 20, 255);
const cv::Scalar kInk(20, 20, 20, 255);
const cv::Scalar kPaper(255, 255, 255, 255);
const cv::Scalar kFrame(150, 150, 150, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

cv::Mat as_mat(std::vector<uint8_t>& rgba, const PlanFrame& frame) {
  return cv::Mat(frame.height_px, frame.width_px, CV_8UC4, rgba.data());
}

int text_width(const std::string& text, const PlanStyle& style) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, style.font_scale, style.thickness, &baseline).width;
}

void put_text(cv::Mat& image, const std::string& text, int x, int baseline_y,
              const PlanStyle& style) {
  cv::putText(image, text, cv::Point(x, baseline_y), kFont, style.font_scale, kInk, style.thickness,
              cv::LINE_AA);
}

const cv::Scalar& colour_of(PlanPath::Kind kind) {
  switch (kind) {
    case PlanPath::Kind::kTruth:
      return kTruthColour;
    case PlanPath::Kind::kUncertain:
      return kUncertainColour;
    case PlanPath::Kind::kEstimate:
      break;
  }
  return kEstimateColour;
}

}  // namespace

PlanStyle plan_style(int side_px) {
  PlanStyle style;
  style.font_scale = std::clamp(side_px / 1400.0, 0.45, 2.0);
  style.thickness = std::max(1, static_cast<int>(std::lround(style.font_scale * 1.6)));
  int baseline = 0;
  style.text_height =
      cv::getTextSize("0m", kFont, style.font_scale, style.thickness, &baseline).height;
  style.gap = std::max(4, style.text_height / 2);
  style.path_width = std::max(2, static_cast<int>(std::lround(side_px / 500.0)));
  return style;
}

int legend_height_px(const PlanStyle& style, size_t paths) {
  return static_cast<int>(paths + 2) * (style.text_height + style.gap) + style.gap;
}

int scale_bar_height_px(const PlanStyle& style) {
  return style.text_height + std::max(3, style.text_height / 2) + 3 * style.gap;
}

std::string length_text(double metres) {
  char text[32];
  if (metres < 1.0) {
    std::snprintf(text, sizeof(text), "%g cm", std::round(metres * 1000.0) / 10.0);
  } else if (metres >= 1000.0) {
    std::snprintf(text, sizeof(text), "%g km", metres / 1000.0);
  } else {
    std::snprintf(text, sizeof(text), "%g m", metres);
  }
  return text;
}

void draw_grid(std::vector<uint8_t>& rgba, const PlanFrame& frame, double spacing_m) {
  const int width = std::max(frame.width_px, frame.height_px) > 2500 ? 2 : 1;
  const auto blend = [&](int column, int row) {
    uint8_t* pixel = &rgba[4 * frame.index(column, row)];
    for (int k = 0; k < 3; ++k) pixel[k] = static_cast<uint8_t>((pixel[k] * 11 + 110 * 9) / 20);
  };
  const double max_x = frame.min_x_m + frame.width_px * frame.pixel_size_m;
  for (double x = std::ceil(frame.min_x_m / spacing_m) * spacing_m; x < max_x; x += spacing_m) {
    const int column = static_cast<int>(std::floor(frame.column_of(x)));
    for (int c = column; c < std::min(column + width, frame.width_px); ++c)
      for (int row = 0; row < frame.height_px; ++row) blend(c, row);
  }
  const double min_y = frame.max_y_m - frame.height_px * frame.pixel_size_m;
  for (double y = std::ceil(min_y / spacing_m) * spacing_m; y < frame.max_y_m; y += spacing_m) {
    const int row = static_cast<int>(std::floor(frame.row_of(y)));
    for (int r = std::max(row, 0); r < std::min(row + width, frame.height_px); ++r)
      for (int column = 0; column < frame.width_px; ++column) blend(column, r);
  }
}

void draw_paths(std::vector<uint8_t>& rgba, const PlanFrame& frame, const PlanStyle& style,
                const std::vector<PlanPath>& paths) {
  cv::Mat image = as_mat(rgba, frame);
  // Sub-pixel positions: OpenCV's fixed point with 4 fractional bits.
  constexpr int kShift = 4;
  constexpr double kScale = 1 << kShift;
  // The truth first, wider: where an estimate lies on it, both show (red edged in blue).
  for (const PlanPath::Kind kind :
       {PlanPath::Kind::kTruth, PlanPath::Kind::kUncertain, PlanPath::Kind::kEstimate}) {
    const int line = kind == PlanPath::Kind::kTruth ? style.path_width + 2 : style.path_width;
    for (const PlanPath& path : paths) {
      if (path.kind != kind) continue;
      bool started = false;
      std::vector<cv::Point> points;
      const auto draw_piece = [&] {
        if (points.empty()) return;
        cv::polylines(image, points, false, colour_of(kind), line, cv::LINE_AA, kShift);
        // The path's start as a dot; a piece after a gap starts without one.
        if (!started) {
          cv::circle(image, points.front(), static_cast<int>((line + 2) * kScale), colour_of(kind),
                     cv::FILLED, cv::LINE_AA, kShift);
        }
        started = true;
        points.clear();
      };
      for (const Eigen::Vector3d& p : path.positions_m) {
        if (!p.allFinite()) {
          draw_piece();
          continue;
        }
        const cv::Point point(static_cast<int>(std::lround(frame.column_of(p.x()) * kScale)),
                              static_cast<int>(std::lround(frame.row_of(p.y()) * kScale)));
        if (points.empty() || point != points.back()) points.push_back(point);
      }
      draw_piece();
    }
  }
}

void draw_scale_bar(std::vector<uint8_t>& rgba, const PlanFrame& frame, const PlanStyle& style,
                    double length_m) {
  cv::Mat image = as_mat(rgba, frame);
  const int bar = std::max(2, static_cast<int>(std::lround(length_m / frame.pixel_size_m)));
  const int bar_height = std::max(3, style.text_height / 2);
  const std::string text = length_text(length_m);
  const int box_width = std::max(bar, text_width(text, style)) + 2 * style.gap;
  const int box_height = scale_bar_height_px(style);
  const int left = style.gap;
  const int top = frame.height_px - style.gap - box_height;
  cv::rectangle(image, cv::Rect(left, top, box_width, box_height), kPaper, cv::FILLED);
  cv::rectangle(image, cv::Rect(left, top, box_width, box_height), kFrame, 1);
  put_text(image, text, left + (box_width - text_width(text, style)) / 2,
           top + style.gap + style.text_height, style);
  const int bar_top = top + 2 * style.gap + style.text_height;
  cv::rectangle(image, cv::Rect(left + style.gap, bar_top, bar, bar_height), kInk, cv::FILLED);
}

PlanRampLegend height_ramp_legend(const HeightRange& colours) {
  char low[32];
  char high[32];
  // Rounded first, so that a floor a millimetre below zero reads 0.0, not -0.0.
  const auto decimetres = [](double z) { return std::round(z * 10.0) / 10.0 + 0.0; };
  std::snprintf(low, sizeof(low), "z %.1f m", decimetres(colours.low_m));
  std::snprintf(high, sizeof(high), "%.1f m", decimetres(colours.high_m));
  return {low, high, height_colour};
}

void draw_legend(std::vector<uint8_t>& rgba, const PlanFrame& frame, const PlanStyle& style,
                 const std::vector<PlanPath>& paths, const PlanLegend& legend) {
  cv::Mat image = as_mat(rgba, frame);
  const int sample = 3 * style.text_height;  // the short line that stands for a path
  const int ramp = 8 * style.text_height;
  const std::string& low = legend.ramp.low;
  const std::string& high = legend.ramp.high;

  int width = text_width(legend.cut, style);
  for (const PlanPath& path : paths)
    width = std::max(width, sample + style.gap + text_width(path.label, style));
  width = std::max(width, text_width(low, style) + ramp + text_width(high, style) + 2 * style.gap);
  const int row_height = style.text_height + style.gap;
  const cv::Rect box(style.gap, style.gap, width + 2 * style.gap,
                     legend_height_px(style, paths.size()));
  cv::rectangle(image, box, kPaper, cv::FILLED);
  cv::rectangle(image, box, kFrame, 1);

  const int left = box.x + style.gap;
  int baseline = box.y + style.gap + style.text_height;
  for (const PlanPath& path : paths) {
    const int middle = baseline - style.text_height / 2;
    cv::line(image, cv::Point(left, middle), cv::Point(left + sample, middle), colour_of(path.kind),
             style.path_width, cv::LINE_AA);
    put_text(image, path.label, left + sample + style.gap, baseline, style);
    baseline += row_height;
  }
  put_text(image, legend.cut, left, baseline, style);
  baseline += row_height;

  // The colour ramp between its two ends' texts.
  put_text(image, low, left, baseline, style);
  const int ramp_left = left + text_width(low, style) + style.gap;
  for (int x = 0; x < ramp; ++x) {
    const std::array<uint8_t, 3> c = legend.ramp.colour(static_cast<double>(x) / (ramp - 1));
    cv::line(image, cv::Point(ramp_left + x, baseline - style.text_height),
             cv::Point(ramp_left + x, baseline), cv::Scalar(c[0], c[1], c[2], 255));
  }
  put_text(image, high, ramp_left + ramp + style.gap, baseline, style);
}

}  // namespace featsense::viewer_export
