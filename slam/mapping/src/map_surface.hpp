#pragma once
// A saved map's surface, read region by region: the store opened read-only (the file is
// never changed), each chunk's surface cells (surface_cells.hpp) made when a region first
// reaches into it and kept in a cache bounded by bytes, least recently used first out. A
// city's map is never loaded whole: memory is the cache and the index of the chunks' keys.
// Thread-safe: one region at a time.

#include <Eigen/Geometry>

#include <cstddef>
#include <filesystem>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "featsense/storage/hdf5_chunk_store.hpp"
#include "surface_cells.hpp"

namespace featsense::mapping {

struct MapSurfaceCounts {
  size_t chunks_made = 0;    ///< chunks read from the file and turned into cells
  size_t chunks_reused = 0;  ///< found in the cache
  size_t chunks_evicted = 0;
  size_t cached_bytes = 0;  ///< now
  size_t peak_cached_bytes = 0;
  double read_ms = 0.0;  ///< reading and decompressing chunks
  double cells_ms = 0.0;
};

class MapSurface {
 public:
  /// Opens `map` read-only (std::runtime_error naming the file where it cannot be). The
  /// cells are `cell_m` across, of voxels observed at least `min_weight`.
  MapSurface(const std::filesystem::path& map, size_t cache_bytes, double cell_m, double block_m,
             double min_weight);

  const storage::MapMetadata& metadata() const { return store_->metadata(); }
  size_t chunks() const { return chunk_count_; }

  /// The surface of every chunk that reaches into `box` (whole chunks: a little outside the
  /// box comes too).
  std::vector<std::shared_ptr<const ChunkSurface>> surfaces_in(const Eigen::AlignedBox3d& box);

  MapSurfaceCounts counts() const;

 private:
  struct Cached {
    std::shared_ptr<const ChunkSurface> surface;
    std::list<storage::ChunkKey>::iterator lru;
  };
  void evict_to(size_t bytes);

  mutable std::mutex mutex_;
  std::unique_ptr<storage::Hdf5ChunkStore> store_;
  SurfaceSettings settings_;
  size_t cache_bytes_;
  /// The stored chunks' z coordinates by their (x, y) column: which chunks a box reaches
  /// without asking the file.
  std::map<std::pair<int32_t, int32_t>, std::vector<int32_t>> columns_;
  size_t chunk_count_ = 0;
  std::unordered_map<storage::ChunkKey, Cached, storage::ChunkKeyHash> cache_;
  std::list<storage::ChunkKey> lru_;  ///< front: most recently used
  MapSurfaceCounts counts_;
};

}  // namespace featsense::mapping
