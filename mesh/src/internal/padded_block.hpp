#pragma once
/// One chunk with the voxels around it that meshing it needs: one voxel before it (for the
/// central differences of the normals at its lower faces) and two after it (the +1 corners of
/// its last cubes, and their central differences).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "featsense/storage/chunk.hpp"

namespace featsense::mesh::internal {

constexpr int32_t kPaddedSize = storage::kChunkSize + 3;  ///< local coordinates -1 .. 65
constexpr std::size_t kPaddedVoxels =
    static_cast<std::size_t>(kPaddedSize) * kPaddedSize * kPaddedSize;

struct PaddedBlock {
  storage::ChunkKey key;
  std::vector<uint32_t> voxels = std::vector<uint32_t>(kPaddedVoxels, 0u);  ///< x fastest

  /// Index of chunk-local voxel (x, y, z), each in -1 .. 65.
  static std::size_t index(int32_t x, int32_t y, int32_t z) {
    return static_cast<std::size_t>((x + 1) + kPaddedSize * ((y + 1) + kPaddedSize * (z + 1)));
  }
};

}  // namespace featsense::mesh::internal
