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
    // hidden region; their apparent edge belongs to the occluding object.
    for (int col = 0; col + 1 < scan.cols; ++col) {
      if (!valid(col) || !valid(col + 1)) continue;
      const float a = range(col);
      const float b = range(col + 1);
      if (std::abs(a - b) <= jump) continue;
      if (a > b) {
        for (int k = std::max(0, col - n); k <= col; ++k) line[k] = 1;
      } else {
        for (int k = col + 1; k <= std::min(scan.cols - 1, col + 1 + n); ++k) line[k] = 1;
      }
    }
  });
  return excluded;
}

}  // namespace featsense::slam::features
