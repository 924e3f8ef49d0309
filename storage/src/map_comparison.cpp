#include "featsense/storage/map_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string>

#include "featsense/tsdf/voxel.hpp"

namespace featsense::storage {

MapDifference compare_maps(ChunkStore& first, ChunkStore& second) {
  const MapMetadata& a = first.metadata();
  const MapMetadata& b = second.metadata();
  if (a.voxel_size_m != b.voxel_size_m || a.truncation_m != b.truncation_m) {
    throw std::runtime_error(
        "the maps differ in their grids: voxel " + std::to_string(a.voxel_size_m) + " m, tau " +
        std::to_string(a.truncation_m) + " m against voxel " + std::to_string(b.voxel_size_m) +
        " m, tau " + std::to_string(b.truncation_m) + " m");
  }
  const std::vector<ChunkKey> first_keys = first.keys();
  const std::vector<ChunkKey> second_keys = second.keys();
  const std::set<ChunkKey> in_second(second_keys.begin(), second_keys.end());
  MapDifference out;
  const double metres_per_step = a.truncation_m / tsdf::kValueScale;
  for (const ChunkKey& key : first_keys) {
    if (in_second.count(key) == 0) {
      ++out.chunks_only_first;
      continue;
    }
    const std::optional<Chunk> x = first.read(key);
    const std::optional<Chunk> y = second.read(key);
    if (!x || !y) throw std::runtime_error("a listed chunk could not be read");
    if (*x == *y) {
      ++out.chunks_equal;
      continue;
    }
    ++out.chunks_differing;
    for (size_t i = 0; i < kChunkVoxels; ++i) {
      if (x->voxels[i] == y->voxels[i]) continue;
      ++out.voxels_differing;
      const tsdf::Voxel u = tsdf::unpack(x->voxels[i]);
      const tsdf::Voxel v = tsdf::unpack(y->voxels[i]);
      if ((u.weight == 0) != (v.weight == 0)) {
        ++out.voxels_observed_in_one;
        continue;
      }
      out.largest_value_difference_m =
          std::max(out.largest_value_difference_m, std::abs(u.value - v.value) * metres_per_step);
      out.largest_weight_difference =
          std::max(out.largest_weight_difference,
                   std::abs(u.weight - v.weight) / static_cast<double>(tsdf::kWeightScale));
    }
  }
  const std::set<ChunkKey> in_first(first_keys.begin(), first_keys.end());
  for (const ChunkKey& key : second_keys) out.chunks_only_second += in_first.count(key) == 0;
  return out;
}

}  // namespace featsense::storage
