#include "internal/dense_block_store.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace featsense::mesh::internal {

using storage::ChunkKey;
using storage::kChunkSize;

DenseBlockStore::DenseBlockStore(const std::vector<uint32_t>& voxels, tsdf::Index3 origin,
                                 tsdf::Index3 dim, storage::MapMetadata metadata)
    : voxels_(voxels), origin_(origin), dim_(dim), metadata_(std::move(metadata)) {
  if (dim.x < 0 || dim.y < 0 || dim.z < 0 ||
      voxels.size() !=
          static_cast<size_t>(dim.x) * static_cast<size_t>(dim.y) * static_cast<size_t>(dim.z)) {
    throw std::invalid_argument("dense block: " + std::to_string(voxels.size()) +
                                " voxels for a block of " + std::to_string(dim.x) + " x " +
                                std::to_string(dim.y) + " x " + std::to_string(dim.z));
  }
  if (voxels.empty()) return;
  const ChunkKey first = storage::chunk_of_voxel(origin.x, origin.y, origin.z);
  const ChunkKey last =
      storage::chunk_of_voxel(origin.x + dim.x - 1, origin.y + dim.y - 1, origin.z + dim.z - 1);
  for (int32_t x = first.x; x <= last.x; ++x)
    for (int32_t y = first.y; y <= last.y; ++y)
      for (int32_t z = first.z; z <= last.z; ++z) keys_.push_back({x, y, z});
}

std::optional<storage::Chunk> DenseBlockStore::read(const ChunkKey& key) {
  const int64_t x0 = std::max<int64_t>(int64_t{key.x} * kChunkSize, origin_.x);
  const int64_t y0 = std::max<int64_t>(int64_t{key.y} * kChunkSize, origin_.y);
  const int64_t z0 = std::max<int64_t>(int64_t{key.z} * kChunkSize, origin_.z);
  const int64_t x1 =
      std::min<int64_t>(int64_t{key.x + 1} * kChunkSize, int64_t{origin_.x} + dim_.x);
  const int64_t y1 =
      std::min<int64_t>(int64_t{key.y + 1} * kChunkSize, int64_t{origin_.y} + dim_.y);
  const int64_t z1 =
      std::min<int64_t>(int64_t{key.z + 1} * kChunkSize, int64_t{origin_.z} + dim_.z);
  if (x0 >= x1 || y0 >= y1 || z0 >= z1) return std::nullopt;
  storage::Chunk chunk;
  bool observed = false;
  for (int64_t z = z0; z < z1; ++z)
    for (int64_t y = y0; y < y1; ++y)
      for (int64_t x = x0; x < x1; ++x) {
        const auto source = static_cast<size_t>(
            (x - origin_.x) +
            int64_t{dim_.x} * ((y - origin_.y) + int64_t{dim_.y} * (z - origin_.z)));
        const uint32_t bits = voxels_[source];
        observed = observed || (bits >> 16) != 0u;
        chunk.at(static_cast<int32_t>(x - int64_t{key.x} * kChunkSize),
                 static_cast<int32_t>(y - int64_t{key.y} * kChunkSize),
                 static_cast<int32_t>(z - int64_t{key.z} * kChunkSize)) = bits;
      }
  if (!observed) return std::nullopt;
  return chunk;
}

void DenseBlockStore::write(const ChunkKey& /*key*/, const storage::Chunk& /*chunk*/) {
  throw std::logic_error("dense block store is read-only");
}

}  // namespace featsense::mesh::internal
