#pragma once
/// Points that are never features (paper, after LOAM): out of the range limits, on surfaces
/// nearly parallel to the beam, on the far side of an occlusion.

#include <cstdint>
#include <vector>

#include "featsense/slam/features/feature_extractor.hpp"

namespace featsense::slam::features {

/// rows * cols, 1 where the cell may not become a feature: invalid, range outside
/// [min_range_m, max_range_m], both line gaps above parallel_gap_ratio column spacings
/// (range * 2 pi / cols), or within N cells on the far side of a range jump above
/// occlusion_jump_m to the next cell of the line.
std::vector<uint8_t> excluded_cells(const Scan& scan, const FeatureSettings& settings);

}  // namespace featsense::slam::features
