#include "featsense/tsdf/scan_rays.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::tsdf {
namespace {

using Point = Eigen::Map<const Eigen::Vector3f>;

Point point_at(const OrganizedScanView& scan, size_t i) { return Point(scan.xyz_m + 3 * i); }

/// Whether cell j (the beam above or below cell i) disagrees in range with i by more than a
/// surface facing the sensor at >= ~27 degrees can explain.
bool grazing_or_edge(const OrganizedScanView& scan, size_t i, size_t j) {
  if (!scan.valid[j]) return false;
  const Point p = point_at(scan, i);
  const Point q = point_at(scan, j);
  const float r = p.norm();
  const float rn = q.norm();
  if (!(r > 0.0f) || !(rn > 0.0f)) return false;
  const float cos_angle = std::clamp(p.dot(q) / (r * rn), -1.0f, 1.0f);
  const float angle = std::acos(cos_angle);
  constexpr float kMaxRangeStep = 2.0f;  // in units of range x angle: tan(27 deg) = 1 / 2
  return std::abs(r - rn) > kMaxRangeStep * std::min(r, rn) * angle;
}

}  // namespace

std::vector<uint8_t> vertical_interpolation_flags(const OrganizedScanView& scan) {
  const auto index = [&](int row, int col) {
    return static_cast<size_t>(row) * static_cast<size_t>(scan.cols) + static_cast<size_t>(col);
  };
  std::vector<uint8_t> flags(static_cast<size_t>(scan.rows) * static_cast<size_t>(scan.cols), 1);
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      const size_t i = index(row, col);
      if (!scan.valid[i]) continue;
      const bool above = row > 0 && grazing_or_edge(scan, i, index(row - 1, col));
      const bool below = row + 1 < scan.rows && grazing_or_edge(scan, i, index(row + 1, col));
      if (above || below) flags[i] = 0;
    }
  }
  return flags;
}

uint8_t carving_level(int row, int col) {
  const auto level = [](int index) {
    return index == 0 ? int{kFullCarvingLevel} : __builtin_ctz(static_cast<unsigned>(index));
  };
  return static_cast<uint8_t>(std::min({level(row), level(col), int{kFullCarvingLevel}}));
}

}  // namespace featsense::tsdf
