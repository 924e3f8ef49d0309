#pragma once
/// A chunk store held in memory: for tests, previews and maps small enough to never need a
/// file. Same semantics as the HDF5 store (an empty chunk removes its key); flush does nothing.

#include <map>

#include "featsense/storage/chunk_store.hpp"

namespace featsense::storage {

class MemoryChunkStore final : public ChunkStore {
 public:
  explicit MemoryChunkStore(MapMetadata metadata) : metadata_(std::move(metadata)) {}

  std::optional<Chunk> read(const ChunkKey& key) override;
  void write(const ChunkKey& key, const Chunk& chunk) override;
  std::vector<ChunkKey> keys() const override;
  void flush() override {}
  const MapMetadata& metadata() const override { return metadata_; }

 private:
  MapMetadata metadata_;
  std::map<ChunkKey, Chunk> chunks_;
};

}  // namespace featsense::storage
