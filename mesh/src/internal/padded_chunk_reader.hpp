#pragma once
/// Reads chunks with their 26 neighbours from a chunk store, one caller at a time, keeping
/// recently read chunks so that each is read about once when keys come in sorted order; and
/// assembles a chunk's padded block from them (any thread).

#include <array>
#include <cstdint>
#include <list>
#include <memory>
#include <set>
#include <unordered_map>
#include <vector>

#include "featsense/storage/chunk_store.hpp"
#include "internal/padded_block.hpp"

namespace featsense::mesh::internal {

/// A chunk and its neighbours, index (dx + 1) + 3 (dy + 1) + 9 (dz + 1); null where absent.
struct ChunkNeighbourhood {
  storage::ChunkKey key;
  std::array<std::shared_ptr<const storage::Chunk>, 27> chunks;
};

class PaddedChunkReader {
 public:
  /// `keys`: every stored key, sorted (the order chunks will be asked for). Keeps up to
  /// twelve columns of chunks (along z) in memory, which covers the neighbours of consecutive
  /// chunks in that order.
  PaddedChunkReader(storage::ChunkStore& store, const std::vector<storage::ChunkKey>& keys);

  ChunkNeighbourhood read(const storage::ChunkKey& key);

  std::size_t chunk_reads() const { return reads_; }

 private:
  std::shared_ptr<const storage::Chunk> chunk(const storage::ChunkKey& key);

  struct Cached {
    std::shared_ptr<const storage::Chunk> chunk;
    std::list<storage::ChunkKey>::iterator position;
  };

  storage::ChunkStore& store_;
  std::set<storage::ChunkKey> present_;
  std::size_t capacity_ = 0;
  std::list<storage::ChunkKey> lru_;  ///< front = most recently used
  std::unordered_map<storage::ChunkKey, Cached, storage::ChunkKeyHash> cache_;
  std::size_t reads_ = 0;
};

/// False when no cube of the chunk can get a face: the observed voxels its cubes reach (its
/// own and the lower faces of its +x/+y/+z neighbours) are all on one side of the surface.
/// Much cheaper than padding and marching a chunk of free space.
bool may_have_faces(const ChunkNeighbourhood& neighbourhood, uint32_t min_weight_fixed);

/// The chunk with one voxel before and two after it; unobserved where no chunk is stored.
void fill_padded_block(const ChunkNeighbourhood& neighbourhood, PaddedBlock& block);

}  // namespace featsense::mesh::internal
