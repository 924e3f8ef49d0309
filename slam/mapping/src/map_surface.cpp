#include "map_surface.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <utility>

namespace featsense::mapping {
namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

int32_t chunk_floor(double metres, double chunk_m) {
  return static_cast<int32_t>(std::floor(metres / chunk_m));
}

/// Chunks are read and turned into cells this many at a time: the file is read by one
/// thread, the cells made by all.
constexpr size_t kBatch = 32;

}  // namespace

MapSurface::MapSurface(const std::filesystem::path& map, size_t cache_bytes, double cell_m,
                       double block_m, double min_weight)
    : cache_bytes_(cache_bytes) {
  storage::StoreSettings store_settings;
  // The store's own cache holds whole chunks (1 MiB each); the cells are cached here.
  store_settings.cache_bytes = 2 * storage::kChunkBytes;
  store_ = std::make_unique<storage::Hdf5ChunkStore>(map, store_settings);
  settings_.voxel_m = store_->metadata().voxel_size_m;
  settings_.truncation_m = store_->metadata().truncation_m;
  settings_.cell_m = cell_m;
  settings_.block_m = block_m;
  settings_.min_weight = min_weight;
  for (const storage::ChunkKey& key : store_->keys()) {
    columns_[{key.x, key.y}].push_back(key.z);
    ++chunk_count_;
  }
}

void MapSurface::evict_to(size_t bytes) {
  while (counts_.cached_bytes > bytes && !lru_.empty()) {
    const storage::ChunkKey key = lru_.back();
    lru_.pop_back();
    const auto it = cache_.find(key);
    counts_.cached_bytes -= it->second.surface->bytes();
    cache_.erase(it);
    ++counts_.chunks_evicted;
  }
}

std::vector<std::shared_ptr<const ChunkSurface>> MapSurface::surfaces_in(
    const Eigen::AlignedBox3d& box) {
  std::lock_guard<std::mutex> lock(mutex_);
  const double chunk_m = settings_.voxel_m * storage::kChunkSize;
  const Eigen::Vector3d lo = box.min(), hi = box.max();
  std::vector<storage::ChunkKey> wanted;
  for (int32_t x = chunk_floor(lo.x(), chunk_m); x <= chunk_floor(hi.x(), chunk_m); ++x) {
    for (int32_t y = chunk_floor(lo.y(), chunk_m); y <= chunk_floor(hi.y(), chunk_m); ++y) {
      const auto column = columns_.find({x, y});
      if (column == columns_.end()) continue;
      for (const int32_t z : column->second) {
        if (z >= chunk_floor(lo.z(), chunk_m) && z <= chunk_floor(hi.z(), chunk_m))
          wanted.push_back({x, y, z});
      }
    }
  }
  std::vector<std::shared_ptr<const ChunkSurface>> parts;
  std::vector<storage::ChunkKey> missing;
  for (const storage::ChunkKey& key : wanted) {
    const auto it = cache_.find(key);
    if (it == cache_.end()) {
      missing.push_back(key);
      continue;
    }
    lru_.splice(lru_.begin(), lru_, it->second.lru);
    parts.push_back(it->second.surface);
    ++counts_.chunks_reused;
  }
  for (size_t first = 0; first < missing.size(); first += kBatch) {
    const size_t end = std::min(missing.size(), first + kBatch);
    std::vector<std::optional<storage::Chunk>> chunks(end - first);
    const auto read_start = std::chrono::steady_clock::now();
    for (size_t i = first; i < end; ++i) chunks[i - first] = store_->read(missing[i]);
    counts_.read_ms += ms_since(read_start);
    const auto cells_start = std::chrono::steady_clock::now();
    std::vector<std::shared_ptr<ChunkSurface>> made(chunks.size());
    tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t i) {
      made[i] = std::make_shared<ChunkSurface>();
      if (chunks[i]) *made[i] = chunk_surface(missing[first + i], *chunks[i], settings_);
    });
    counts_.cells_ms += ms_since(cells_start);
    for (size_t i = 0; i < made.size(); ++i) {
      const storage::ChunkKey& key = missing[first + i];
      lru_.push_front(key);
      cache_[key] = Cached{made[i], lru_.begin()};
      counts_.cached_bytes += made[i]->bytes();
      parts.push_back(made[i]);
      ++counts_.chunks_made;
    }
  }
  counts_.peak_cached_bytes = std::max(counts_.peak_cached_bytes, counts_.cached_bytes);
  // The region asked for stays whole even where it is larger than the cache: the cache
  // keeps what fits of it, the most recently used first.
  evict_to(cache_bytes_);
  return parts;
}

MapSurfaceCounts MapSurface::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return counts_;
}

}  // namespace featsense::mapping
