#pragma once
/// Picking edges and surfaces along one scan line, sector by sector.

#include <cstdint>
#include <vector>

#include "featsense/slam/features/feature_extractor.hpp"

namespace featsense::slam::features {

struct LinePicks {
  std::vector<int> edges;  ///< columns
  std::vector<int> surfaces;
};

/// One line of `cols` cells: `curvature` (normalised, NaN where none) and `excluded` (1: never
/// a feature) point at its first cell. The line's columns that have a curvature are cut into
/// `sectors` equal parts; in each, edges are the highest curvatures in (edge_threshold,
/// max_edge_threshold), at most max_edges_per_sector, then surfaces the lowest below
/// surface_threshold, at most max_surfaces_per_sector. A picked point's +/- N neighbours are
/// not picked afterwards (either kind), which spreads the features evenly.
LinePicks select_line_features(const float* curvature, const uint8_t* excluded, int cols,
                               const FeatureSettings& settings);

}  // namespace featsense::slam::features
