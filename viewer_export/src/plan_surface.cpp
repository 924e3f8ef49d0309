#include "internal/plan_surface.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace featsense::viewer_export {
namespace {

/// |n.z| below which a triangle counts as steep: more than about 70 degrees from level.
constexpr float kSteep = 0.35f;
/// A wall whose top is this close to a flat surface's height wins the pixel, so that the sides
/// of a table outline its top.
constexpr float kWallTieM = 1e-3f;

struct Projected {
  double column[3];
  double row[3];
  double z[3];
  double z_min;
  double z_max;
};

class Rasterizer {
 public:
  Rasterizer(const PlanFrame& frame, const CutHeightField& cut, PlanSurface& out)
      : frame_(frame), cut_(cut), out_(out) {}

  /// A level or sloping triangle: the pixels whose centres it covers, at its height there.
  void fill(const Projected& t, int32_t triangle, uint8_t light) {
    const double area = (t.column[1] - t.column[0]) * (t.row[2] - t.row[0]) -
                        (t.column[2] - t.column[0]) * (t.row[1] - t.row[0]);
    if (std::abs(area) < 1e-12) return;
    int c0, c1, r0, r1;
    if (!pixel_bounds(t, &c0, &c1, &r0, &r1)) return;
    for (int r = r0; r <= r1; ++r) {
      const double y = r + 0.5;
      for (int c = c0; c <= c1; ++c) {
        const double x = c + 0.5;
        const double w0 =
            ((t.column[1] - x) * (t.row[2] - y) - (t.column[2] - x) * (t.row[1] - y)) / area;
        const double w1 =
            ((t.column[2] - x) * (t.row[0] - y) - (t.column[0] - x) * (t.row[2] - y)) / area;
        const double w2 = 1.0 - w0 - w1;
        if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
        const double z = w0 * t.z[0] + w1 * t.z[1] + w2 * t.z[2];
        if (z > cut_at(t, c, r)) continue;
        const size_t i = frame_.index(c, r);
        if (std::isnan(out_.height_m[i]) || z > out_.height_m[i]) {
          out_.height_m[i] = static_cast<float>(z);
          out_.light[i] = light;
          out_.is_wall[i] = 0;
          out_.triangle[i] = triangle;
        }
      }
    }
  }

  /// A steep triangle: every pixel its outline passes through (sampled every half pixel along
  /// its edges) and those whose centres it covers, at its top or at the cut.
  void cover(const Projected& t, int32_t triangle, uint8_t light) {
    for (int e = 0; e < 3; ++e) {
      const int f = (e + 1) % 3;
      const double length = std::hypot(t.column[f] - t.column[e], t.row[f] - t.row[e]);
      const int steps = static_cast<int>(std::ceil(2.0 * length)) + 1;
      for (int s = 0; s <= steps; ++s) {
        const double k = static_cast<double>(s) / steps;
        const double column = t.column[e] + k * (t.column[f] - t.column[e]);
        const double row = t.row[e] + k * (t.row[f] - t.row[e]);
        mark_wall(t, static_cast<int>(std::floor(column)), static_cast<int>(std::floor(row)),
                  triangle, light);
      }
    }
    const double area = (t.column[1] - t.column[0]) * (t.row[2] - t.row[0]) -
                        (t.column[2] - t.column[0]) * (t.row[1] - t.row[0]);
    if (std::abs(area) < 1.0) return;  // a sliver: its edges covered it
    int c0, c1, r0, r1;
    if (!pixel_bounds(t, &c0, &c1, &r0, &r1)) return;
    for (int r = r0; r <= r1; ++r) {
      for (int c = c0; c <= c1; ++c) {
        const double x = c + 0.5;
        const double y = r + 0.5;
        const double w0 =
            ((t.column[1] - x) * (t.row[2] - y) - (t.column[2] - x) * (t.row[1] - y)) / area;
        const double w1 =
            ((t.column[2] - x) * (t.row[0] - y) - (t.column[0] - x) * (t.row[2] - y)) / area;
        if (w0 >= 0.0 && w1 >= 0.0 && w0 + w1 <= 1.0) mark_wall(t, c, r, triangle, light);
      }
    }
  }

 private:
  bool pixel_bounds(const Projected& t, int* c0, int* c1, int* r0, int* r1) const {
    *c0 = std::max(0,
                   static_cast<int>(std::floor(std::min({t.column[0], t.column[1], t.column[2]}))));
    *c1 = std::min(frame_.width_px - 1,
                   static_cast<int>(std::floor(std::max({t.column[0], t.column[1], t.column[2]}))));
    *r0 = std::max(0, static_cast<int>(std::floor(std::min({t.row[0], t.row[1], t.row[2]}))));
    *r1 = std::min(frame_.height_px - 1,
                   static_cast<int>(std::floor(std::max({t.row[0], t.row[1], t.row[2]}))));
    return *c0 <= *c1 && *r0 <= *r1;
  }

  /// The cut at a pixel; not looked up for triangles below every cut.
  double cut_at(const Projected& t, int column, int row) const {
    if (t.z_max <= cut_.lowest_m()) return std::numeric_limits<double>::infinity();
    return cut_.at(frame_.x_of(column), frame_.y_of(row));
  }

  void mark_wall(const Projected& t, int column, int row, int32_t triangle, uint8_t light) {
    if (column < 0 || row < 0 || column >= frame_.width_px || row >= frame_.height_px) return;
    const double cut = cut_at(t, column, row);
    if (t.z_min > cut) return;
    const float z = static_cast<float>(std::min(t.z_max, cut));
    const size_t i = frame_.index(column, row);
    if (std::isnan(out_.height_m[i]) || z >= out_.height_m[i] - kWallTieM) {
      out_.height_m[i] = z;
      out_.light[i] = light;
      out_.is_wall[i] = 1;
      out_.triangle[i] = triangle;
    }
  }

  const PlanFrame& frame_;
  const CutHeightField& cut_;
  PlanSurface& out_;
};

}  // namespace

PlanSurface rasterize_below_cut(const mesh::TriangleMesh& mesh, const PlanFrame& frame,
                                const CutHeightField& cut) {
  PlanSurface out;
  out.height_m.assign(frame.pixels(), std::numeric_limits<float>::quiet_NaN());
  out.light.assign(frame.pixels(), 0);
  out.is_wall.assign(frame.pixels(), 0);
  out.triangle.assign(frame.pixels(), -1);
  Rasterizer rasterizer(frame, cut, out);
  // From the upper left of the image (north-west) and 45 degrees up, as hill-shaded maps are.
  const Eigen::Vector3d to_light = Eigen::Vector3d(-1.0, 1.0, std::sqrt(2.0)).normalized();
  const bool smooth = mesh.has_normals();
  for (size_t index = 0; index < mesh.triangles.size(); ++index) {
    const Eigen::Vector3i& triangle = mesh.triangles[index];
    const Eigen::Vector3f* v[3];
    for (int k = 0; k < 3; ++k) v[k] = &mesh.vertices[static_cast<size_t>(triangle[k])];
    const Eigen::Vector3f face = (*v[1] - *v[0]).cross(*v[2] - *v[0]);
    const float length = face.norm();
    if (!(length > 0.0f)) continue;
    Projected t;
    t.z_min = std::min({v[0]->z(), v[1]->z(), v[2]->z()});
    t.z_max = std::max({v[0]->z(), v[1]->z(), v[2]->z()});
    if (t.z_min > cut.highest_m()) continue;  // above the cut everywhere: a ceiling
    for (int k = 0; k < 3; ++k) {
      t.column[k] = frame.column_of(v[k]->x());
      t.row[k] = frame.row_of(v[k]->y());
      t.z[k] = v[k]->z();
    }
    // The side seen from above faces up; smooth normals shade marching cubes' facets evenly.
    Eigen::Vector3d normal = face.cast<double>() / length;
    if (smooth) {
      const Eigen::Vector3f sum = mesh.normals[static_cast<size_t>(triangle[0])] +
                                  mesh.normals[static_cast<size_t>(triangle[1])] +
                                  mesh.normals[static_cast<size_t>(triangle[2])];
      if (sum.norm() > 1e-6f) normal = sum.cast<double>().normalized();
    }
    if (normal.z() < 0.0) normal = -normal;
    const uint8_t light =
        static_cast<uint8_t>(std::lround(255.0 * std::clamp(normal.dot(to_light), 0.0, 1.0)));
    if (std::abs(face.z()) / length < kSteep) {
      rasterizer.cover(t, static_cast<int32_t>(index), light);
    } else {
      rasterizer.fill(t, static_cast<int32_t>(index), light);
    }
  }
  return out;
}

}  // namespace featsense::viewer_export
