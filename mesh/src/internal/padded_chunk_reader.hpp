#pragma once
/// Reads chunks with their neighbourhood from a chunk store, one caller at a time, and tells
/// which chunks cannot hold a face (all their observed voxels, and those of the neighbour
/// faces their cubes reach, on one side of the surface).

#include <cstdint>
#include <list>
#include <memory>
#include <optional>
#include <set>
#include <unordered_map>
#include <vector>

#include "featsense/storage/chunk_store.hpp"
#include "internal/padded_block.hpp"

namespace featsense::mesh::internal {

class PaddedChunkReader {
 public:
  /// `keys`: the stored keys, sorted, in the order they will be asked for. Keeps up to about
  /// twelve rows of chunks (along z) in memory, which covers the neighbours of consecutive
  /// chunks in that order.
  PaddedChunkReader(storage::ChunkStore& store, uint32_t min_weight_fixed,
                    const std::vector<storage::ChunkKey>& keys);

  /// The chunk with one voxel before and two after it, or nothing when none of its cubes can
  /// have a face.
  std::unique_ptr<PaddedBlock> read(const storage::ChunkKey& key);

  std::size_t chunk_reads() const { return reads_; }

 private:
  /// Which signs the observed voxels have: bit 0 negative, bit 1 not negative.
  struct Signs {
    uint8_t all = 0;          ///< over the whole chunk
    uint8_t lower_faces = 0;  ///< over its x = 0, y = 0 and z = 0 planes
  };

  std::shared_ptr<const storage::Chunk> chunk(const storage::ChunkKey& key);
  Signs signs(const storage::ChunkKey& key);
  Signs measure_signs(const storage::Chunk& chunk) const;
  void copy_neighbour(const storage::Chunk& chunk, int dx, int dy, int dz,
                      PaddedBlock& block) const;

  storage::ChunkStore& store_;
  uint32_t min_weight_fixed_;
  std::set<storage::ChunkKey> present_;
  std::unordered_map<storage::ChunkKey, Signs, storage::ChunkKeyHash> signs_;
  std::size_t capacity_ = 0;
  std::list<storage::ChunkKey> lru_;  ///< front = most recently used
  struct Cached {
    std::shared_ptr<const storage::Chunk> chunk;
    std::list<storage::ChunkKey>::iterator position;
  };
  std::unordered_map<storage::ChunkKey, Cached, storage::ChunkKeyHash> cache_;
  std::size_t reads_ = 0;
};

}  // namespace featsense::mesh::internal
