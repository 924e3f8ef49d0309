#pragma once
/// Points that are never features (paper, after LOAM): out of the range limits, on surfaces
/// nearly parallel to the beam, on the far side of an occlusion.

#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "featsense/slam/features/feature_extractor.hpp"

namespace featsense::slam::features {

/// Every per-cell array of the scan (points, ranges, valid flags) has a cell for each of its
/// rows * cols, and it has some: the scans the filters and the extractor can read.
bool well_formed(const Scan& scan);

/// rows * cols, 1 where the cell may not become a feature: invalid, range outside
/// [min_range_m, max_range_m], both line gaps above parallel_gap_ratio column spacings
/// (range * 2 pi / cols), or within N cells of a range jump above occlusion_jump_m to the
/// next cell of the line, on either side.
std::vector<uint8_t> excluded_cells(const Scan& scan, const FeatureSettings& settings);

/// The occluding boundaries: rows * cols, +1 at the near cell of a range jump above
/// occlusion_jump_m whose far side is the next column, -1 where it is the previous one, 0
/// elsewhere; only where the near cell is within the range limits, the N cells behind it on
/// its own side are valid and follow on without a jump (a face that ends there), and the gap to
/// the first of them is within parallel_gap_ratio column spacings (a face not nearly parallel
/// to the beam).
///
/// Why: the face's true end lies somewhere between the near cell's ray and the far cell's, so
/// the near cell is short of it by half a column on average, inwards. Seen from a moving sensor
/// that shortfall changes with the range and the angle (the map's points were seen from
/// farther away): cars, posts and building corners passed at a few metres then pull every
/// registration back along the travel (the simulated parking drive's odometry measured its
/// path 0.1 % short on exact ranges). The cells just inside the boundary were no better: their
/// curvature counted the far side's points and the edge picked among them lay up to N columns
/// inside.
std::vector<int8_t> occluding_boundaries(const Scan& scan, const FeatureSettings& settings);

/// Where the face of an occluding boundary (row, col, side from occluding_boundaries) ends,
/// estimated without bias: the near cell moved half a column further along the face, the face's
/// direction taken over its last N cells (N: `n`) so that one return's range noise moves it
/// little.
Eigen::Vector3f boundary_point(const Scan& scan, int row, int col, int side, int n);

}  // namespace featsense::slam::features
