#include "featsense/slam/features/feature_filters.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace featsense::slam::features {

namespace {

/// One scan line, by column.
struct Line {
  const Scan& scan;
  int row;
  bool valid(int col) const { return scan.valid[scan.index(row, col)] != 0; }
  float range(int col) const { return scan.range_m[scan.index(row, col)]; }
  const Eigen::Vector3f& point(int col) const { return scan.xyz[scan.index(row, col)]; }
};

/// A gap to a line neighbour beyond this times the range lies on a surface nearly parallel to
/// the beam: parallel_gap_ratio times the spacing of neighbouring columns on a surface facing
/// the beam, per metre of range.
float parallel_gap_per_m(const Scan& scan, const FeatureSettings& settings) {
  const float column_angle = static_cast<float>(2.0 * M_PI / scan.cols);
  return static_cast<float>(settings.parallel_gap_ratio) * column_angle;
}

/// Calls at_jump(col) for each column whose cell and the next are valid and not within
/// occlusion_jump_m of each other in range (a range that is not a number included).
template <class AtJump>
void for_each_jump(const Line& line, const FeatureSettings& settings, AtJump&& at_jump) {
  const float jump = static_cast<float>(settings.occlusion_jump_m);
  for (int col = 0; col + 1 < line.scan.cols; ++col) {
    if (!line.valid(col) || !line.valid(col + 1)) continue;
    if (std::abs(line.range(col) - line.range(col + 1)) <= jump) continue;
    at_jump(col);
  }
}

}  // namespace

bool well_formed(const Scan& scan) {
  return scan.rows > 0 && scan.cols > 0 && scan.xyz.size() == scan.size() &&
         scan.range_m.size() == scan.size() && scan.valid.size() == scan.size();
}

std::vector<uint8_t> excluded_cells(const Scan& scan, const FeatureSettings& settings) {
  std::vector<uint8_t> excluded(scan.size(), 1);
  if (!well_formed(scan)) return excluded;
  const int n = settings.neighbours;
  const float parallel_gap = parallel_gap_per_m(scan, settings);
  const float min_range = static_cast<float>(settings.min_range_m);
  const float max_range = static_cast<float>(settings.max_range_m);

  tbb::parallel_for(0, scan.rows, [&](int row) {
    uint8_t* cells = excluded.data() + scan.index(row, 0);
    const Line line{scan, row};
    for (int col = 0; col < scan.cols; ++col) {
      cells[col] = !line.valid(col) || line.range(col) < min_range || line.range(col) > max_range;
    }
    // Surfaces nearly parallel to the beam: both gaps much larger than the column spacing.
    for (int col = 1; col + 1 < scan.cols; ++col) {
      if (cells[col] || !line.valid(col - 1) || !line.valid(col + 1)) continue;
      const float limit = parallel_gap * line.range(col);
      if ((line.point(col) - line.point(col - 1)).norm() > limit &&
          (line.point(col + 1) - line.point(col)).norm() > limit) {
        cells[col] = 1;
      }
    }
    // Occlusions: the far side of a range jump and its N neighbours there lie next to a
    // hidden region; their apparent edge belongs to the occluding object. The near side's N
    // cells have the far side among their neighbours: a curvature that measures the jump, not
    // the object's shape (their own edge is the boundary, occluding_boundaries()).
    for_each_jump(line, settings, [&](int col) {
      for (int k = std::max(0, col - n); k <= col; ++k) cells[k] = 1;
      for (int k = col + 1; k <= std::min(scan.cols - 1, col + 1 + n); ++k) cells[k] = 1;
    });
  });
  return excluded;
}

std::vector<int8_t> occluding_boundaries(const Scan& scan, const FeatureSettings& settings) {
  std::vector<int8_t> side(scan.size(), 0);
  if (!well_formed(scan)) return side;
  const int n = std::max(settings.neighbours, 1);
  const float jump = static_cast<float>(settings.occlusion_jump_m);
  const float parallel_gap = parallel_gap_per_m(scan, settings);
  const float min_range = static_cast<float>(settings.min_range_m);
  const float max_range = static_cast<float>(settings.max_range_m);
  tbb::parallel_for(0, scan.rows, [&](int row) {
    const Line line{scan, row};
    // The near cell of a jump, where the N cells behind it on its side are valid and follow
    // on without a jump: a face that ends there, not a lone return (a wire, a leaf); and not
    // one nearly parallel to the beam, whose end lies anywhere within its wide gaps.
    auto face_behind = [&](int col, int step) {
      for (int k = 1; k <= n; ++k) {
        const int c = col - step * k;
        if (c < 0 || c >= scan.cols || !line.valid(c)) return false;
        if (!(std::abs(line.range(c) - line.range(c + step)) <= jump)) return false;  // NaN too
      }
      return (line.point(col) - line.point(col - step)).norm() <= parallel_gap * line.range(col);
    };
    for_each_jump(line, settings, [&](int col) {
      const float a = line.range(col);
      const float b = line.range(col + 1);
      if (!std::isfinite(a) || !std::isfinite(b)) return;  // no jump to judge
      const int near = a < b ? col : col + 1;
      const int step = a < b ? 1 : -1;  // from the near cell towards the far side
      if (line.range(near) < min_range || line.range(near) > max_range) return;
      if (face_behind(near, step)) side[scan.index(row, near)] = static_cast<int8_t>(step);
    });
  });
  return side;
}

Eigen::Vector3f boundary_point(const Scan& scan, int row, int col, int side, int n) {
  const Eigen::Vector3f& p = scan.xyz[scan.index(row, col)];
  const Eigen::Vector3f& behind = scan.xyz[scan.index(row, col - side * n)];
  return p + (0.5f / static_cast<float>(n)) * (p - behind);
}

}  // namespace featsense::slam::features
