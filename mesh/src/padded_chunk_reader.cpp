#include "internal/padded_chunk_reader.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <optional>
#include <utility>

namespace featsense::mesh::internal {
namespace {

using storage::ChunkKey;
using storage::kChunkSize;

/// The most chunks of one (x, y) column: the neighbours of one chunk span 3 x 3 columns, and
/// those of the next chunks in sorted order mostly the same ones.
std::size_t longest_column(const std::vector<ChunkKey>& keys) {
  std::map<std::pair<int32_t, int32_t>, std::size_t> counts;
  std::size_t longest = 1;
  for (const ChunkKey& key : keys) longest = std::max(longest, ++counts[{key.x, key.y}]);
  return longest;
}

/// Copies the part of a neighbour (offset dx, dy, dz in chunks) that lies in the padded block:
/// per axis its last voxel (offset -1), all of it (0) or its first two voxels (+1).
void copy_neighbour(const storage::Chunk& chunk, int dx, int dy, int dz, PaddedBlock& block) {
  auto range = [](int offset, int32_t& from, int32_t& to) {
    from = offset < 0 ? kChunkSize - 1 : 0;
    to = offset > 0 ? 2 : kChunkSize;
  };
  int32_t x0 = 0, x1 = 0, y0 = 0, y1 = 0, z0 = 0, z1 = 0;
  range(dx, x0, x1);
  range(dy, y0, y1);
  range(dz, z0, z1);
  const auto count = static_cast<std::size_t>(x1 - x0);
  for (int32_t z = z0; z < z1; ++z)
    for (int32_t y = y0; y < y1; ++y) {
      const uint32_t* source = chunk.voxels.data() + storage::Chunk::index(x0, y, z);
      uint32_t* target =
          block.voxels.data() +
          PaddedBlock::index(x0 + dx * kChunkSize, y + dy * kChunkSize, z + dz * kChunkSize);
      std::copy(source, source + count, target);
    }
}

}  // namespace

PaddedChunkReader::PaddedChunkReader(storage::ChunkStore& store, const std::vector<ChunkKey>& keys)
    : store_(store),
      present_(keys.begin(), keys.end()),
      capacity_(12 * longest_column(keys) + 27) {}

std::shared_ptr<const storage::Chunk> PaddedChunkReader::chunk(const ChunkKey& key) {
  if (present_.count(key) == 0) return nullptr;
  auto found = cache_.find(key);
  if (found != cache_.end()) {
    lru_.splice(lru_.begin(), lru_, found->second.position);
    return found->second.chunk;
  }
  std::optional<storage::Chunk> read = store_.read(key);
  ++reads_;
  if (!read) {
    present_.erase(key);
    return nullptr;
  }
  auto shared = std::make_shared<const storage::Chunk>(std::move(*read));
  lru_.push_front(key);
  cache_[key] = Cached{shared, lru_.begin()};
  while (cache_.size() > capacity_) {
    cache_.erase(lru_.back());
    lru_.pop_back();
  }
  return shared;
}

ChunkNeighbourhood PaddedChunkReader::read(const ChunkKey& key) {
  ChunkNeighbourhood out;
  out.key = key;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        out.chunks[static_cast<std::size_t>((dx + 1) + 3 * (dy + 1) + 9 * (dz + 1))] =
            chunk({key.x + dx, key.y + dy, key.z + dz});
      }
  return out;
}

void fill_padded_block(const ChunkNeighbourhood& neighbourhood, PaddedBlock& block) {
  block.key = neighbourhood.key;
  std::fill(block.voxels.begin(), block.voxels.end(), 0u);
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const auto& neighbour =
            neighbourhood.chunks[static_cast<std::size_t>((dx + 1) + 3 * (dy + 1) + 9 * (dz + 1))];
        if (neighbour) copy_neighbour(*neighbour, dx, dy, dz, block);
      }
}

}  // namespace featsense::mesh::internal
