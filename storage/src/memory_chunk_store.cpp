#include "featsense/storage/memory_chunk_store.hpp"

namespace featsense::storage {

std::optional<Chunk> MemoryChunkStore::read(const ChunkKey& key) {
  const auto found = chunks_.find(key);
  if (found == chunks_.end()) return std::nullopt;
  return found->second;
}

void MemoryChunkStore::write(const ChunkKey& key, const Chunk& chunk) {
  if (is_empty(chunk)) {
    chunks_.erase(key);
  } else {
    chunks_[key] = chunk;
  }
}

std::vector<ChunkKey> MemoryChunkStore::keys() const {
  std::vector<ChunkKey> keys;
  keys.reserve(chunks_.size());
  for (const auto& [key, chunk] : chunks_) keys.push_back(key);
  return keys;
}

}  // namespace featsense::storage
