#pragma once
// The scores of a comparison from its counts, shared by the whole and the by-region
// comparison so that both report the same way (the accuracy: distance_accumulator.hpp).

#include <cstddef>
#include <vector>

#include "featsense/mesh/compare_to_reference.hpp"

namespace featsense::mesh::internal {

/// Precision from `points_within` (per threshold, of result->points), completeness from
/// `samples_within` (per threshold, of result->reference_samples), and the F-scores.
void fill_scores(const CompareSettings& settings, const std::vector<size_t>& points_within,
                 const std::vector<size_t>& samples_within, CompareResult* result);

}  // namespace featsense::mesh::internal
