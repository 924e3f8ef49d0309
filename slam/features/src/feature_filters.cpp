#include "featsense/slam/features/feature_filters.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace featsense::slam::features {

std::vector<uint8_t> excluded_cells(const Scan& scan, const FeatureSettings& settings) {
  std::vector<uint8_t> excluded(scan.size(), 1);
  if (scan.size() == 0 || scan.xyz.size() != scan.size() || scan.valid.size() != scan.size() ||
      scan.range_m.size() != scan.size()) {
    return excluded;
  }
  const int n = settings.neighbours;
  // The spacing of neighbouring columns on a surface facing the beam, per metre of range.
  const float column_angle = static_cast<float>(2.0 * M_PI / scan.cols);
  const float parallel_gap = static_cast<float>(settings.parallel_gap_ratio) * column_angle;
  const float jump = static_cast<float>(settings.occlusion_jump_m);
  const float min_range = static_cast<float>(settings.min_range_m);
  const float max_range = static_cast<float>(settings.max_range_m);

  tbb::parallel_for(0, scan.rows, [&](int row) {
    uint8_t* line = excluded.data() + scan.index(row, 0);
    auto valid = [&](int col) { return scan.valid[scan.index(row, col)] != 0; };
    auto range = [&](int col) { return scan.range_m[scan.index(row, col)]; };
    auto point = [&](int col) -> const Eigen::Vector3f& { return scan.xyz[scan.index(row, col)]; };

    for (int col = 0; col < scan.cols; ++col) {
      line[col] = !valid(col) || range(col) < min_range || range(col) > max_range;
    }
    // Surfaces nearly parallel to the beam: both gaps much larger than the column spacing.
    for (int col = 1; col + 1 < scan.cols; ++col) {
      if (line[col] || !valid(col - 1) || !valid(col + 1)) continue;
      const float limit = parallel_gap * range(col);
      if ((point(col) - point(col - 1)).norm() > limit &&
          (point(col + 1) - point(col)).norm() > limit) {
        line[col] = 1;
      }
    }
    // Occlusions: the far side of a range jump and its N neighbours there lie next to a
    // hidden region; their apparent edge belongs to the occluding object. The near side's N
    // cells have the far side among their neighbours: a curvature that measures the jump, not
    // the object's shape (their own edge is the boundary, occluding_boundaries()).
    for (int col = 0; col + 1 < scan.cols; ++col) {
      if (!valid(col) || !valid(col + 1)) continue;
      const float a = range(col);
      const float b = range(col + 1);
      if (std::abs(a - b) <= jump) continue;
      for (int k = std::max(0, col - n); k <= col; ++k) line[k] = 1;
      for (int k = col + 1; k <= std::min(scan.cols - 1, col + 1 + n); ++k) line[k] = 1;
    }
  });
  return excluded;
}

std::vector<int8_t> occluding_boundaries(const Scan& scan, const FeatureSettings& settings) {
  std::vector<int8_t> side(scan.size(), 0);
  if (scan.size() == 0 || scan.xyz.size() != scan.size() || scan.valid.size() != scan.size() ||
      scan.range_m.size() != scan.size()) {
    return side;
  }
  const int n = std::max(settings.neighbours, 1);
  const float jump = static_cast<float>(settings.occlusion_jump_m);
  const float parallel_gap =
      static_cast<float>(settings.parallel_gap_ratio * 2.0 * M_PI / scan.cols);
  const float min_range = static_cast<float>(settings.min_range_m);
  const float max_range = static_cast<float>(settings.max_range_m);
  tbb::parallel_for(0, scan.rows, [&](int row) {
    auto valid = [&](int col) { return scan.valid[scan.index(row, col)] != 0; };
    auto range = [&](int col) { return scan.range_m[scan.index(row, col)]; };
    auto point = [&](int col) -> const Eigen::Vector3f& { return scan.xyz[scan.index(row, col)]; };
    // The near cell of a jump, where the N cells behind it on its side are valid and follow
    // on without a jump: a face that ends there, not a lone return (a wire, a leaf); and not
    // one nearly parallel to the beam, whose end lies anywhere within its wide gaps.
    auto face_behind = [&](int col, int step) {
      for (int k = 1; k <= n; ++k) {
        const int c = col - step * k;
        if (c < 0 || c >= scan.cols || !valid(c)) return false;
        if (!(std::abs(range(c) - range(c + step)) <= jump)) return false;  // NaN too
      }
      return (point(col) - point(col - step)).norm() <= parallel_gap * range(col);
    };
    for (int col = 0; col + 1 < scan.cols; ++col) {
      if (!valid(col) || !valid(col + 1)) continue;
      const float a = range(col);
      const float b = range(col + 1);
      if (std::abs(a - b) <= jump) continue;
      if (!std::isfinite(a) || !std::isfinite(b)) continue;  // no jump to judge
      const int near = a < b ? col : col + 1;
      const int step = a < b ? 1 : -1;  // from the near cell towards the far side
      if (range(near) < min_range || range(near) > max_range) continue;
      if (face_behind(near, step)) side[scan.index(row, near)] = static_cast<int8_t>(step);
    }
  });
  return side;
}

Eigen::Vector3f boundary_point(const Scan& scan, int row, int col, int side, int n) {
  const Eigen::Vector3f& p = scan.xyz[scan.index(row, col)];
  const Eigen::Vector3f& behind = scan.xyz[scan.index(row, col - side * n)];
  return p + (0.5f / static_cast<float>(n)) * (p - behind);
}

}  // namespace featsense::slam::features
