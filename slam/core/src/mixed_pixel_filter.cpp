#include "featsense/slam/preprocess/mixed_pixel_filter.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace featsense::slam {
namespace {

/// The range of cell (row, col) with columns wrapping around (a full revolution), or -1 when
/// the cell holds no return.
float range_at(const Scan& scan, int row, int col) {
  const int c = (col % scan.cols + scan.cols) % scan.cols;
  const size_t i = scan.index(row, c);
  return scan.valid[i] ? scan.range_m[i] : -1.0f;
}

bool is_mixed(const float r[5], const MixedPixelSettings& s) {
  for (int k = 0; k < 5; ++k) {
    if (r[k] < 0.0f) return false;
  }
  const double near = std::min(r[1], r[3]);
  const double far = std::max(r[1], r[3]);
  const double jump = far - near;
  if (jump <= s.min_jump_m) return false;
  if (std::abs(r[0] - r[1]) > s.flat_fraction * jump) return false;
  if (std::abs(r[4] - r[3]) > s.flat_fraction * jump) return false;
  const double margin = std::max(s.margin_m, s.margin_fraction * jump);
  return r[2] > near + margin && r[2] < far - margin;
}

}  // namespace

size_t drop_mixed_pixels(Scan& scan, const MixedPixelSettings& settings) {
  if (scan.cols < 5 || scan.range_m.size() != scan.size()) return 0;
  // Decide on the original ranges first: dropping as we go would change the neighbours of
  // the cells still to be judged.
  std::vector<size_t> mixed;
  for (int row = 0; row < scan.rows; ++row) {
    for (int col = 0; col < scan.cols; ++col) {
      if (!scan.valid[scan.index(row, col)]) continue;
      float r[5];
      for (int k = 0; k < 5; ++k) r[k] = range_at(scan, row, col + k - 2);
      if (is_mixed(r, settings)) mixed.push_back(scan.index(row, col));
    }
  }
  for (const size_t i : mixed) scan.invalidate(i);
  return mixed.size();
}

}  // namespace featsense::slam
