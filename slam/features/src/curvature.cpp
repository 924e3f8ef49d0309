#include "featsense/slam/features/curvature.hpp"

#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

namespace featsense::slam::features {
namespace {

constexpr float kNone = std::numeric_limits<float>::quiet_NaN();

/// sum_{j != i} (P_j - P_i) over the +/- n neighbours and sum_j |P_j - P_i|; false when the
/// neighbourhood leaves the row or holds an invalid cell.
bool neighbourhood_sums(const Scan& scan, int row, int col, int n, Eigen::Vector3f& sum,
                        float& spread) {
  if (n < 1 || col - n < 0 || col + n >= scan.cols) return false;
  const size_t centre = scan.index(row, col);
  if (!scan.valid[centre]) return false;
  const Eigen::Vector3f& p = scan.xyz[centre];
  sum.setZero();
  spread = 0.0f;
  for (int j = col - n; j <= col + n; ++j) {
    if (j == col) continue;
    const size_t k = scan.index(row, j);
    if (!scan.valid[k]) return false;
    const Eigen::Vector3f d = scan.xyz[k] - p;
    sum += d;
    spread += d.norm();
  }
  return true;
}

}  // namespace

float raw_curvature(const Scan& scan, int row, int col, int n) {
  Eigen::Vector3f sum;
  float spread = 0.0f;
  if (!neighbourhood_sums(scan, row, col, n, sum, spread)) return kNone;
  return sum.squaredNorm();
}

float normalised_curvature(const Scan& scan, int row, int col, int n) {
  Eigen::Vector3f sum;
  float spread = 0.0f;
  if (!neighbourhood_sums(scan, row, col, n, sum, spread)) return kNone;
  if (!(spread > 0.0f)) return kNone;  // all neighbours on the point itself: no line
  return sum.squaredNorm() / (spread * spread);
}

std::vector<float> curvature_image(const Scan& scan, int n) {
  std::vector<float> curvature(scan.size(), kNone);
  if (scan.size() == 0 || scan.xyz.size() != scan.size() || scan.valid.size() != scan.size()) {
    return curvature;
  }
  tbb::parallel_for(0, scan.rows, [&](int row) {
    for (int col = n; col + n < scan.cols; ++col) {
      curvature[scan.index(row, col)] = normalised_curvature(scan, row, col, n);
    }
  });
  return curvature;
}

}  // namespace featsense::slam::features
