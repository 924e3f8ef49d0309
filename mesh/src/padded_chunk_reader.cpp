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

/// Copies the part of a neighbour (offset dx, dy, dz in chunks) that lies in the padded block,
/// or zeros (unobserved) where there is none: per axis its last voxel (offset -1), all of it
/// (0) or its first two voxels (+1).
void copy_neighbour(const storage::Chunk* chunk, int dx, int dy, int dz, PaddedBlock& block) {
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
      uint32_t* target =
          block.voxels.data() +
          PaddedBlock::index(x0 + dx * kChunkSize, y + dy * kChunkSize, z + dz * kChunkSize);
      if (chunk == nullptr) {
        std::fill(target, target + count, 0u);
      } else {
        const uint32_t* source = chunk->voxels.data() + storage::Chunk::index(x0, y, z);
        std::copy(source, source + count, target);
      }
    }
}

/// Sign bits of the observed voxels among `count` voxels `stride` apart: bit 0 negative,
/// bit 1 not negative. Branch-free so that the compiler vectorises the contiguous case.
uint32_t observed_signs(const uint32_t* voxels, std::size_t count, std::size_t stride,
                        uint32_t observed_from) {
  uint32_t negative = 0;
  uint32_t positive = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const uint32_t bits = voxels[i * stride];
    const uint32_t observed = bits >= observed_from ? 1u : 0u;
    const uint32_t sign = (bits >> 15) & 1u;
    negative |= observed & sign;
    positive |= observed & (sign ^ 1u);
  }
  return negative | (positive << 1);
}

}  // namespace

bool may_have_faces(const ChunkNeighbourhood& neighbourhood, uint32_t min_weight_fixed) {
  const uint32_t observed_from = min_weight_fixed << 16;
  const auto& own = neighbourhood.chunks[13];
  if (!own) return false;
  constexpr std::size_t kPlane = static_cast<std::size_t>(kChunkSize) * kChunkSize;
  uint32_t signs = 0;
  // Plane by plane, so that a chunk with a surface is found out early.
  for (int32_t z = 0; z < kChunkSize && signs != 3u; ++z)
    signs |= observed_signs(own->voxels.data() + z * kPlane, kPlane, 1, observed_from);
  if (signs == 3u) return true;
  for (int dz = 0; dz <= 1; ++dz)
    for (int dy = 0; dy <= 1; ++dy)
      for (int dx = 0; dx <= 1; ++dx) {
        const auto& chunk =
            neighbourhood.chunks[static_cast<std::size_t>((dx + 1) + 3 * (dy + 1) + 9 * (dz + 1))];
        if (dx + dy + dz == 0 || !chunk) continue;
        const uint32_t* v = chunk->voxels.data();
        // The z = 0 plane is contiguous; the y = 0 plane is 64 rows a plane apart; the x = 0
        // plane is every 64th voxel.
        signs |= observed_signs(v, kPlane, 1, observed_from);
        for (int32_t z = 0; z < kChunkSize; ++z)
          signs |= observed_signs(v + storage::Chunk::index(0, 0, z), kChunkSize, 1, observed_from);
        signs |= observed_signs(v, kPlane, kChunkSize, observed_from);
        if (signs == 3u) return true;
      }
  return signs == 3u;
}

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
  // Every voxel of the block is written below (a copy or a zero); the voxels before -1 and
  // after 65 do not exist, so no clearing of the whole block is needed.
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const auto& neighbour =
            neighbourhood.chunks[static_cast<std::size_t>((dx + 1) + 3 * (dy + 1) + 9 * (dz + 1))];
        copy_neighbour(neighbour.get(), dx, dy, dz, block);
      }
}

}  // namespace featsense::mesh::internal
