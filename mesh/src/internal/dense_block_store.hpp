#pragma once
/// A dense block of packed voxels (the local map, unwrapped) seen as a read-only chunk store,
/// so that it is meshed by the same code as the global map.

#include <vector>

#include "featsense/storage/chunk_store.hpp"
#include "featsense/tsdf/vec3.hpp"

namespace featsense::mesh::internal {

class DenseBlockStore final : public storage::ChunkStore {
 public:
  /// `voxels`: x fastest, voxel (x, y, z) of the block is global voxel origin + (x, y, z).
  /// Throws std::invalid_argument when the size does not match `dim`.
  DenseBlockStore(const std::vector<uint32_t>& voxels, tsdf::Index3 origin, tsdf::Index3 dim,
                  storage::MapMetadata metadata);

  std::optional<storage::Chunk> read(const storage::ChunkKey& key) override;
  void write(const storage::ChunkKey& key, const storage::Chunk& chunk) override;
  std::vector<storage::ChunkKey> keys() const override { return keys_; }
  void flush() override {}
  const storage::MapMetadata& metadata() const override { return metadata_; }

 private:
  const std::vector<uint32_t>& voxels_;
  tsdf::Index3 origin_;
  tsdf::Index3 dim_;
  storage::MapMetadata metadata_;
  std::vector<storage::ChunkKey> keys_;
};

}  // namespace featsense::mesh::internal
