#pragma once
/// Curvature along a scan line (paper eq. 1) and its normalised form used for the thresholds.

#include <vector>

#include "featsense/slam/scan.hpp"

namespace featsense::slam::features {

/// Paper eq. 1 at (row, col): |sum_{j in S, j != i} P_j - |S| P_i|^2 with S the +/- n
/// neighbours on the row, in m^2. NaN unless all 2n + 1 cells are valid and on the row.
float raw_curvature(const Scan& scan, int row, int col, int n);

/// Eq. 1 divided by (sum_j |P_j - P_i|)^2: dimensionless in [0, 1]. 0 on a straight line,
/// cos^2(a / 2) at the corner of a polyline whose legs meet at angle a (evenly spaced on
/// each leg). Eq. 1 itself grows with the square of the point spacing, which is
/// range * 2 pi / cols: dividing by range^2 alone would still leave a factor of 8 between a
/// 360- and a 1024-column sensor; this form needs one threshold for every range, beam and
/// column count and every N. NaN where raw_curvature is.
float normalised_curvature(const Scan& scan, int row, int col, int n);

/// normalised_curvature of every cell, rows * cols (NaN where none), rows in parallel.
std::vector<float> curvature_image(const Scan& scan, int n);

}  // namespace featsense::slam::features
