#include "internal/plan_shading.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace featsense::viewer_export {
namespace {

constexpr uint8_t kEmpty = 250;
constexpr uint8_t kWall = 40;
constexpr uint8_t kOutline = 90;
/// A height difference between neighbouring pixels that is an object's edge, not a slope.
constexpr float kStepM = 0.15f;
/// How wide walls are drawn (at least a pixel, at most four): a marching-cubes wall is one
/// pixel thin, too faint beside the floor's colours.
constexpr double kWallLineM = 0.1;
constexpr double kMinColourSpanM = 1.0;
/// The light of a wall in a picture coloured per vertex: it comes out a fifth darker than a
/// level floor.
constexpr uint8_t kWallLight = 120;

double percentile(std::vector<float> values, double q) {
  const size_t k = static_cast<size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

/// The walls, widened to kWallLineM.
std::vector<uint8_t> widened_walls(const PlanSurface& surface, const PlanFrame& frame) {
  std::vector<uint8_t> walls = surface.is_wall;
  const int width =
      std::clamp(static_cast<int>(std::lround(kWallLineM / frame.pixel_size_m)), 1, 4);
  if (width > 1) {
    const cv::Mat mask(frame.height_px, frame.width_px, CV_8UC1, walls.data());
    cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(width, width)));
  }
  return walls;
}

/// True where a neighbour (4-connected) is lower by more than a step: the upper edge of one.
bool on_step(const PlanSurface& surface, const PlanFrame& frame, int column, int row) {
  const float h = surface.height_m[frame.index(column, row)];
  const int dc[4] = {1, -1, 0, 0};
  const int dr[4] = {0, 0, 1, -1};
  for (int k = 0; k < 4; ++k) {
    const int c = column + dc[k];
    const int r = row + dr[k];
    if (c < 0 || r < 0 || c >= frame.width_px || r >= frame.height_px) continue;
    const float n = surface.height_m[frame.index(c, r)];
    if (n < h - kStepM) return true;  // false for NaN: the edge of what was seen is no step
  }
  return false;
}

/// A colour lit by the pixel's light: a flat floor keeps it, slopes towards the light brighten,
/// away darken.
void shade_into(const std::array<uint8_t, 3>& colour, uint8_t light, uint8_t* pixel) {
  const double shade = 0.4 + 0.6 * light / double{PlanSurface::kFlatLight};
  for (int k = 0; k < 3; ++k) {
    pixel[k] = static_cast<uint8_t>(
        std::clamp(std::lround(colour[static_cast<size_t>(k)] * shade), 0L, 255L));
  }
}

}  // namespace

HeightRange colour_range(const PlanSurface& surface) {
  // A sample of at most ~1 M level pixels is as good as all of them for two percentiles.
  const size_t stride = std::max<size_t>(1, surface.height_m.size() / 1000000);
  std::vector<float> heights;
  for (size_t i = 0; i < surface.height_m.size(); i += stride) {
    if (!std::isnan(surface.height_m[i]) && !surface.is_wall[i])
      heights.push_back(surface.height_m[i]);
  }
  HeightRange range;
  if (heights.empty()) return range;
  range.low_m = percentile(heights, 0.02);
  range.high_m = std::max(percentile(heights, 0.98), range.low_m + kMinColourSpanM);
  return range;
}

std::array<uint8_t, 3> height_colour(double t) {
  static const double kStops[][3] = {{0.78, 0.85, 0.93},
                                     {0.72, 0.88, 0.76},
                                     {0.93, 0.92, 0.66},
                                     {0.96, 0.77, 0.53},
                                     {0.85, 0.58, 0.48}};
  constexpr int kSegments = 4;
  const double x = std::clamp(t, 0.0, 1.0) * kSegments;
  const int i = std::min(static_cast<int>(x), kSegments - 1);
  const double f = x - i;
  std::array<uint8_t, 3> colour{};
  for (int k = 0; k < 3; ++k) {
    colour[static_cast<size_t>(k)] = static_cast<uint8_t>(
        std::lround(255.0 * (kStops[i][k] + f * (kStops[i + 1][k] - kStops[i][k]))));
  }
  return colour;
}

std::vector<uint8_t> shade_plan(const PlanSurface& surface, const PlanFrame& frame,
                                const HeightRange& range) {
  const std::vector<uint8_t> walls = widened_walls(surface, frame);
  std::vector<uint8_t> rgba(frame.pixels() * 4, 255);
  for (int row = 0; row < frame.height_px; ++row) {
    for (int column = 0; column < frame.width_px; ++column) {
      const size_t i = frame.index(column, row);
      uint8_t* pixel = &rgba[4 * i];
      const float h = surface.height_m[i];
      if (walls[i]) {
        std::fill(pixel, pixel + 3, kWall);
      } else if (std::isnan(h)) {
        std::fill(pixel, pixel + 3, kEmpty);
      } else if (on_step(surface, frame, column, row)) {
        std::fill(pixel, pixel + 3, kOutline);
      } else {
        shade_into(height_colour((h - range.low_m) / (range.high_m - range.low_m)),
                   surface.light[i], pixel);
      }
    }
  }
  return rgba;
}

std::vector<uint8_t> shade_plan_by_vertex(
    const PlanSurface& surface, const PlanFrame& frame, const mesh::TriangleMesh& mesh,
    const std::vector<Eigen::Matrix<uint8_t, 3, 1>>& vertex_rgb) {
  std::vector<uint8_t> rgba(frame.pixels() * 4, 255);
  for (int row = 0; row < frame.height_px; ++row) {
    for (int column = 0; column < frame.width_px; ++column) {
      const size_t i = frame.index(column, row);
      uint8_t* pixel = &rgba[4 * i];
      const int32_t t = surface.triangle[i];
      if (t < 0) {
        std::fill(pixel, pixel + 3, kEmpty);
        continue;
      }
      const bool wall = surface.is_wall[i] != 0;
      // A wall's top is a step above the floor beside it: walls keep their own colour.
      if (!wall && on_step(surface, frame, column, row)) {
        std::fill(pixel, pixel + 3, kOutline);
        continue;
      }
      // Marching cubes' triangles are about a voxel, a pixel or less: their mean colour is as
      // fine as the picture.
      const Eigen::Vector3i& corners = mesh.triangles[static_cast<size_t>(t)];
      std::array<uint8_t, 3> colour{};
      for (size_t k = 0; k < 3; ++k) {
        int sum = 0;
        for (int c = 0; c < 3; ++c)
          sum += vertex_rgb[static_cast<size_t>(corners[c])][static_cast<Eigen::Index>(k)];
        colour[k] = static_cast<uint8_t>((sum + 1) / 3);
      }
      // Walls, seen edge on, are drawn a little darker than level (a wall on the reference
      // is grey beside a white floor); floors and slopes are hill-shaded.
      shade_into(colour, wall ? kWallLight : surface.light[i], pixel);
    }
  }
  return rgba;
}

}  // namespace featsense::viewer_export
