#include "featsense/storage/chunk.hpp"

#include <algorithm>

namespace featsense::storage {

bool is_empty(const Chunk& chunk) {
  // The weight is the high half of the packed voxel.
  return std::all_of(chunk.voxels.begin(), chunk.voxels.end(),
                     [](uint32_t bits) { return (bits >> 16) == 0u; });
}

}  // namespace featsense::storage
