#include "featsense/mesh/map_tiles.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "internal/chunk_set_mesher.hpp"

namespace featsense::mesh {
namespace {

using storage::ChunkKey;
using storage::kChunkSize;

/// floor(a / b) for b > 0, also for negative a.
int32_t floor_div(int32_t a, int32_t b) {
  const int32_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

}  // namespace

int32_t chunks_per_tile_for(double tile_size_m, const storage::MapMetadata& metadata) {
  if (!(tile_size_m > 0.0) || !std::isfinite(tile_size_m)) {
    throw std::invalid_argument("tile size must be a positive number of metres, got " +
                                std::to_string(tile_size_m));
  }
  if (!(metadata.voxel_size_m > 0.0)) {
    throw std::invalid_argument("map metadata: voxel size must be positive");
  }
  const double chunk_m = metadata.voxel_size_m * kChunkSize;
  const double chunks = std::round(tile_size_m / chunk_m);
  return static_cast<int32_t>(std::clamp(chunks, 1.0, 1e6));
}

MapTiles::MapTiles(storage::ChunkStore& store, int32_t chunks_per_tile)
    : store_(store), chunks_per_tile_(chunks_per_tile), keys_(store.keys()) {
  if (chunks_per_tile < 1) {
    throw std::invalid_argument("a tile holds at least one chunk per side, got " +
                                std::to_string(chunks_per_tile));
  }
  std::sort(keys_.begin(), keys_.end());
}

TileIndex MapTiles::tile_of(const ChunkKey& key) const {
  return {floor_div(key.x, chunks_per_tile_), floor_div(key.y, chunks_per_tile_)};
}

std::vector<TileIndex> MapTiles::tiles() const {
  std::vector<TileIndex> tiles;
  for (const ChunkKey& key : keys_) {
    const TileIndex tile = tile_of(key);
    if (tiles.empty() || !(tiles.back() == tile)) tiles.push_back(tile);
  }
  // Keys sorted by x then y give runs per column of chunks, not per tile.
  std::sort(tiles.begin(), tiles.end());
  tiles.erase(std::unique(tiles.begin(), tiles.end()), tiles.end());
  return tiles;
}

double MapTiles::tile_size_m() const {
  return store_.metadata().voxel_size_m * kChunkSize * chunks_per_tile_;
}

std::vector<ChunkKey> MapTiles::keys_in(int32_t x0, int32_t x1, int32_t y0, int32_t y1) const {
  std::vector<ChunkKey> keys;
  auto it = std::lower_bound(keys_.begin(), keys_.end(),
                             ChunkKey{x0, y0, std::numeric_limits<int32_t>::min()});
  for (; it != keys_.end() && it->x <= x1; ++it) {
    if (it->y >= y0 && it->y <= y1) keys.push_back(*it);
  }
  return keys;
}

double MapTiles::cut_m(int32_t tile) const {
  // As marching cubes computes a vertex on it: the voxel's centre index, exact in double, times
  // the voxel size.
  const double centre = static_cast<double>(tile) * chunks_per_tile_ * kChunkSize + 0.5;
  return centre * store_.metadata().voxel_size_m;
}

std::size_t MapTiles::chunk_count(TileIndex tile) const {
  const int32_t x0 = tile.x * chunks_per_tile_;
  const int32_t y0 = tile.y * chunks_per_tile_;
  return keys_in(x0, x0 + chunks_per_tile_ - 1, y0, y0 + chunks_per_tile_ - 1).size();
}

Eigen::AlignedBox3d MapTiles::bounds(TileIndex tile) const {
  const double voxel = store_.metadata().voxel_size_m;
  const int32_t x0 = tile.x * chunks_per_tile_;
  const int32_t y0 = tile.y * chunks_per_tile_;
  const std::vector<ChunkKey> keys =
      keys_in(x0, x0 + chunks_per_tile_ - 1, y0, y0 + chunks_per_tile_ - 1);
  int32_t z0 = 0;
  int32_t z1 = -1;
  if (!keys.empty()) {
    z0 = std::numeric_limits<int32_t>::max();
    z1 = std::numeric_limits<int32_t>::min();
    for (const ChunkKey& key : keys) {
      z0 = std::min(z0, key.z);
      z1 = std::max(z1, key.z);
    }
  }
  // Cubes of voxel g span the centres g + 0.5 .. g + 1.5: the first cube's lower centre to the
  // last cube's upper one, which is the next tile's first centre.
  const auto edge = [&](int32_t first_chunk) {
    return (static_cast<double>(first_chunk) * kChunkSize + 0.5) * voxel;
  };
  return {Eigen::Vector3d(cut_m(tile.x), cut_m(tile.y), edge(z0)),
          Eigen::Vector3d(cut_m(tile.x + 1), cut_m(tile.y + 1), edge(z1 + 1))};
}

TriangleMesh MapTiles::mesh(TileIndex tile, const MeshingSettings& settings,
                            MeshingStats* stats) const {
  const auto start = std::chrono::steady_clock::now();
  const storage::MapMetadata& metadata = store_.metadata();
  internal::check_meshing_settings(settings, metadata);
  const int32_t x0 = tile.x * chunks_per_tile_;
  const int32_t y0 = tile.y * chunks_per_tile_;
  const int32_t x1 = x0 + chunks_per_tile_ - 1;
  const int32_t y1 = y0 + chunks_per_tile_ - 1;
  // The tile's chunks and the ring of columns around it, whose voxels its border cubes and
  // normals reach.
  const std::vector<ChunkKey> readable = keys_in(x0 - 1, x1 + 1, y0 - 1, y1 + 1);
  std::vector<ChunkKey> own;
  for (const ChunkKey& key : readable) {
    if (key.x >= x0 && key.x <= x1 && key.y >= y0 && key.y <= y1) own.push_back(key);
  }
  const std::vector<internal::ChunkWork> work = internal::chunk_work(own, settings, metadata);
  return internal::mesh_chunk_work(store_, readable, work, settings.threads, start, stats);
}

}  // namespace featsense::mesh
