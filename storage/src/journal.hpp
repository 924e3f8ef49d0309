#pragma once
/// The append-only journal beside the .h5 (`<map>.h5.journal`, layout in FORMAT.md): chunks,
/// trajectories, keyframes and session tables flushed since the last checkpoint. Records end in
/// a CRC-32, so a record torn by a crash is recognised and dropped with everything after it.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "featsense/storage/chunk.hpp"

namespace featsense::storage::detail {

/// kKeyframe: one keyframe, keyed (session, index) in the record key's x and y; a later record
/// of the same key replaces it. kSessions: the whole sessions table; the last one wins.
enum class RecordType : uint32_t { kChunk = 1, kTrajectory = 2, kKeyframe = 3, kSessions = 4 };

struct JournalRecord {
  RecordType type = RecordType::kChunk;
  ChunkKey key;
  uint64_t payload_offset = 0;  ///< bytes from the start of the file
  uint32_t payload_size = 0;    ///< bytes; 0 for a chunk means "removed"
};

class Journal {
 public:
  /// Opens (writable: creating when missing, `truncate`: emptying it) the journal at `path`.
  /// A read-only journal that does not exist reads as empty.
  Journal(const std::filesystem::path& path, bool writable, bool truncate);
  ~Journal();
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  /// Every valid record in file order. A writable journal is cut after the last valid one.
  std::vector<JournalRecord> replay();
  /// Appends a record (not yet durable); returns its payload offset.
  uint64_t append(RecordType type, const ChunkKey& key, const std::vector<uint8_t>& payload);
  /// Makes the appended records durable (fdatasync).
  void sync();
  std::vector<uint8_t> read_payload(uint64_t offset, uint32_t size) const;
  /// Drops every record (after a checkpoint), durably.
  void reset();
  uint64_t size_bytes() const { return end_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  void write_all(const void* data, std::size_t size, uint64_t offset);

  std::filesystem::path path_;
  int fd_ = -1;
  bool writable_ = false;
  uint64_t end_ = 0;  ///< end of the last valid record, bytes
};

}  // namespace featsense::storage::detail
