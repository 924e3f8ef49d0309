#pragma once
/// A chunk of the global map: a cube of 64^3 voxels of the global voxel grid (the grid of
/// tsdf/local_map_geometry.hpp, anchored at the map origin), each packed as
/// featsense::tsdf::pack (value in the low 16 bits, weight in the high 16 bits).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace featsense::storage {

constexpr int32_t kChunkSize = 64;  ///< voxels along each edge of a chunk
constexpr std::size_t kChunkVoxels = static_cast<std::size_t>(kChunkSize) * kChunkSize * kChunkSize;
constexpr std::size_t kChunkBytes = kChunkVoxels * sizeof(uint32_t);  ///< 1 MiB

/// Integer chunk coordinates: chunk of global voxel g = floor(g / 64) per axis.
struct ChunkKey {
  int32_t x = 0;
  int32_t y = 0;
  int32_t z = 0;

  friend bool operator==(const ChunkKey& a, const ChunkKey& b) {
    return a.x == b.x && a.y == b.y && a.z == b.z;
  }
  friend bool operator!=(const ChunkKey& a, const ChunkKey& b) { return !(a == b); }
  friend bool operator<(const ChunkKey& a, const ChunkKey& b) {
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
  }
};

struct ChunkKeyHash {
  std::size_t operator()(const ChunkKey& k) const {
    // Large odd multipliers spread neighbouring keys over the buckets.
    const uint64_t h = static_cast<uint64_t>(static_cast<uint32_t>(k.x)) * 73856093u ^
                       static_cast<uint64_t>(static_cast<uint32_t>(k.y)) * 19349663u ^
                       static_cast<uint64_t>(static_cast<uint32_t>(k.z)) * 83492791u;
    return static_cast<std::size_t>(h);
  }
};

/// The chunk holding a global voxel index (one axis): floor(g / 64), also for negative g.
inline int32_t chunk_coordinate(int64_t global_voxel) {
  return static_cast<int32_t>(global_voxel >= 0 ? global_voxel / kChunkSize
                                                : -((-global_voxel + kChunkSize - 1) / kChunkSize));
}

/// The chunk holding global voxel (gx, gy, gz).
inline ChunkKey chunk_of_voxel(int64_t gx, int64_t gy, int64_t gz) {
  return {chunk_coordinate(gx), chunk_coordinate(gy), chunk_coordinate(gz)};
}

/// 64^3 packed voxels, x fastest: index = x + 64 * (y + 64 * z), local coordinates 0..63.
struct Chunk {
  std::vector<uint32_t> voxels = std::vector<uint32_t>(kChunkVoxels, 0u);

  static std::size_t index(int32_t x, int32_t y, int32_t z) {
    return static_cast<std::size_t>(x) +
           static_cast<std::size_t>(kChunkSize) *
               (static_cast<std::size_t>(y) +
                static_cast<std::size_t>(kChunkSize) * static_cast<std::size_t>(z));
  }
  uint32_t& at(int32_t x, int32_t y, int32_t z) { return voxels[index(x, y, z)]; }
  uint32_t at(int32_t x, int32_t y, int32_t z) const { return voxels[index(x, y, z)]; }

  friend bool operator==(const Chunk& a, const Chunk& b) { return a.voxels == b.voxels; }
};

/// True when no voxel of the chunk was observed (every weight 0); such chunks are never stored.
bool is_empty(const Chunk& chunk);

}  // namespace featsense::storage
