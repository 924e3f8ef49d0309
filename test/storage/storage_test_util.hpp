#pragma once
// Chunks with known contents for the store tests, and the metadata they use.

#include <cstdint>
#include <random>

#include "featsense/storage/chunk.hpp"
#include "featsense/storage/chunk_store.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::test {

/// A chunk whose observed voxels (about a quarter, with runs as a surface band would make)
/// follow from `seed` alone, so a test can rebuild the expected contents independently.
inline storage::Chunk make_chunk(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> value(-32767, 32767);
  std::uniform_int_distribution<int> weight(1, 640);
  std::uniform_int_distribution<int> run(1, 200);
  storage::Chunk chunk;
  std::size_t i = rng() % 1000;
  while (i < storage::kChunkVoxels) {
    const std::size_t length = static_cast<std::size_t>(run(rng));
    for (std::size_t j = i; j < i + length && j < storage::kChunkVoxels; ++j) {
      tsdf::Voxel v;
      v.value = static_cast<int16_t>(value(rng));
      v.weight = static_cast<uint16_t>(weight(rng));
      chunk.voxels[j] = tsdf::pack(v);
    }
    i += length * 4;
  }
  return chunk;
}

inline storage::MapMetadata test_metadata() {
  storage::MapMetadata m;
  m.voxel_size_m = 0.064;
  m.truncation_m = 0.6;
  m.max_weight = 10.0;
  m.sensor = "ouster-os1-64";
  m.config_yaml = "map:\n  voxel_size_m: 0.064\n  truncation_m: 0.6\n";
  return m;
}

}  // namespace featsense::test
