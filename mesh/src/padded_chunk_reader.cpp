#include "internal/padded_chunk_reader.hpp"

#include <algorithm>
#include <cstring>
#include <map>
#include <utility>

namespace featsense::mesh::internal {
namespace {

using storage::ChunkKey;
using storage::kChunkSize;

constexpr uint8_t kNegative = 1;
constexpr uint8_t kPositive = 2;

/// The most chunks of one (x, y) column: the neighbours of one chunk span 3 x 3 columns, and
/// those of the next chunks in sorted order mostly the same ones.
std::size_t longest_column(const std::vector<ChunkKey>& keys) {
  std::map<std::pair<int32_t, int32_t>, std::size_t> counts;
  std::size_t longest = 1;
  for (const ChunkKey& key : keys) longest = std::max(longest, ++counts[{key.x, key.y}]);
  return longest;
}

}  // namespace

PaddedChunkReader::PaddedChunkReader(storage::ChunkStore& store, uint32_t min_weight_fixed,
                                     const std::vector<ChunkKey>& keys)
    : store_(store),
      min_weight_fixed_(min_weight_fixed),
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
  if (signs_.count(key) == 0) signs_[key] = measure_signs(*shared);
  lru_.push_front(key);
  cache_[key] = Cached{shared, lru_.begin()};
  while (cache_.size() > capacity_) {
    cache_.erase(lru_.back());
    lru_.pop_back();
  }
  return shared;
}

PaddedChunkReader::Signs PaddedChunkReader::signs(const ChunkKey& key) {
  auto found = signs_.find(key);
  if (found != signs_.end()) return found->second;
  if (!chunk(key)) return {};
  return signs_[key];
}

PaddedChunkReader::Signs PaddedChunkReader::measure_signs(const storage::Chunk& chunk) const {
  Signs signs;
  for (int32_t z = 0; z < kChunkSize; ++z)
    for (int32_t y = 0; y < kChunkSize; ++y) {
      const uint32_t* row = chunk.voxels.data() + storage::Chunk::index(0, y, z);
      uint8_t row_signs = 0;
      for (int32_t x = 0; x < kChunkSize; ++x) {
        const uint32_t bits = row[x];
        if ((bits >> 16) < min_weight_fixed_) continue;
        const uint8_t sign = (bits & 0x8000u) != 0u ? kNegative : kPositive;  // int16 sign bit
        row_signs |= sign;
        if (x == 0 || y == 0 || z == 0) signs.lower_faces |= sign;
      }
      signs.all |= row_signs;
    }
  return signs;
}

std::unique_ptr<PaddedBlock> PaddedChunkReader::read(const ChunkKey& key) {
  // The cubes of this chunk reach its own voxels and the lower faces of its +x/+y/+z
  // neighbours; without both signs there, no cube changes sign.
  uint8_t reached = signs(key).all;
  for (int dz = 0; dz <= 1; ++dz)
    for (int dy = 0; dy <= 1; ++dy)
      for (int dx = 0; dx <= 1; ++dx) {
        if (dx + dy + dz == 0) continue;
        reached |= signs({key.x + dx, key.y + dy, key.z + dz}).lower_faces;
      }
  if (reached != (kNegative | kPositive)) return nullptr;

  auto block = std::make_unique<PaddedBlock>();
  block->key = key;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const auto neighbour = chunk({key.x + dx, key.y + dy, key.z + dz});
        if (neighbour) copy_neighbour(*neighbour, dx, dy, dz, *block);
      }
  return block;
}

void PaddedChunkReader::copy_neighbour(const storage::Chunk& chunk, int dx, int dy, int dz,
                                       PaddedBlock& block) const {
  // Per axis, the neighbour's voxels [from, to) that land in the padded block at local
  // coordinate (its own coordinate + offset * 64): the last one before, all of it, or the
  // first two after.
  auto range = [](int offset, int32_t& from, int32_t& to) {
    from = offset < 0 ? kChunkSize - 1 : 0;
    to = offset > 0 ? 2 : kChunkSize;
  };
  int32_t x0 = 0, x1 = 0, y0 = 0, y1 = 0, z0 = 0, z1 = 0;
  range(dx, x0, x1);
  range(dy, y0, y1);
  range(dz, z0, z1);
  for (int32_t z = z0; z < z1; ++z)
    for (int32_t y = y0; y < y1; ++y) {
      const uint32_t* source = chunk.voxels.data() + storage::Chunk::index(x0, y, z);
      uint32_t* target =
          block.voxels.data() +
          PaddedBlock::index(x0 + dx * kChunkSize, y + dy * kChunkSize, z + dz * kChunkSize);
      std::memcpy(target, source, static_cast<std::size_t>(x1 - x0) * sizeof(uint32_t));
    }
}

}  // namespace featsense::mesh::internal
