#pragma once
// The figures of a comparison from its distances, shared by the whole and the by-region
// comparison so that both report the same way.

#include <cstddef>
#include <vector>

#include "featsense/mesh/compare_to_reference.hpp"

namespace featsense::mesh::internal {

/// From result->unsigned_distance_m and signed_distance_m: points, beyond_max_dist, accuracy
/// and the histogram.
void fill_accuracy_figures(const CompareSettings& settings, CompareResult* result);

/// Precision from the distances, completeness from `samples_within` (per threshold, of
/// result->reference_samples), and the F-scores.
void fill_scores(const CompareSettings& settings, const std::vector<size_t>& samples_within,
                 CompareResult* result);

}  // namespace featsense::mesh::internal
