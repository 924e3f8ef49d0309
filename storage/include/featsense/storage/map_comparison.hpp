#pragma once
// Two maps of one voxel grid compared chunk by chunk and voxel by voxel: the same map bit for
// bit (a backend against another, a map made again against a full re-map) or where and by how
// much they differ. One chunk of each is in memory at a time.

#include <cstddef>

#include "featsense/storage/chunk_store.hpp"

namespace featsense::storage {

struct MapDifference {
  size_t chunks_equal = 0;      ///< in both, every voxel the same
  size_t chunks_differing = 0;  ///< in both, some voxel not
  size_t chunks_only_first = 0;
  size_t chunks_only_second = 0;
  size_t voxels_differing = 0;              ///< of chunks in both: observed in either, not the same
  size_t voxels_observed_in_one = 0;        ///< of those: observed (weight > 0) in one map only
  double largest_value_difference_m = 0.0;  ///< of voxels observed in both, metres
  double largest_weight_difference = 0.0;   ///< of voxels observed in both
  bool identical() const {
    return chunks_differing == 0 && chunks_only_first == 0 && chunks_only_second == 0;
  }
};

/// Compares `first` and `second`; their voxel size and tau must be the same (else
/// std::runtime_error naming both).
MapDifference compare_maps(ChunkStore& first, ChunkStore& second);

}  // namespace featsense::storage
