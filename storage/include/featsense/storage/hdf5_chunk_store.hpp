#pragma once
/// The global map in an HDF5 file (layout in storage/FORMAT.md) with a journal beside it
/// (`<path>.journal`) that makes every flush durable: after a crash at any moment the map
/// opens with every chunk flushed before it. Recently used chunks stay in an LRU cache. The
/// file also keeps the trajectory, the sessions that made the map and their keyframes.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "featsense/storage/chunk_store.hpp"
#include "featsense/storage/map_sessions.hpp"

namespace featsense::storage {

namespace detail {
class Journal;
class Hdf5MapReader;
class Hdf5MapWriter;
}  // namespace detail

enum class OpenMode {
  kCreate,           ///< a new map; an error if the file exists
  kCreateOverwrite,  ///< a new map, replacing an existing file and its journal
  kAppend,           ///< continue an existing map; metadata must match
  kReadOnly,         ///< read an existing map; writes are errors
};

struct StoreSettings {
  std::size_t cache_bytes = std::size_t{256} << 20;  ///< LRU limit, bytes (>= one chunk kept)
  /// A flush folds the journal into the .h5 once the journal is this large, bytes, and also
  /// larger than half the .h5: a fold rewrites the whole file, so a journal that may grow with
  /// the file keeps the folds' cost in proportion to what was journalled (each journalled byte
  /// is written at most three times), where a fixed limit made a long route's map quadratic.
  std::size_t journal_limit_bytes = std::size_t{512} << 20;
  /// Fold the journal into the .h5 at close. Off only to leave the map as a crash would.
  bool checkpoint_on_close = true;
  /// 0-9, for the .h5 chunk datasets and the journal records. 1: compressing evicted chunks
  /// is a tenth of a CPU mapping run; level 3 made the parking drive's map 4 % smaller and
  /// its mapping 6 % slower on 2 cores.
  int deflate_level = 1;
};

class Hdf5ChunkStore;

/// Writes a new map file at `into`, replacing any map there and its journal: `newer`'s
/// metadata, trajectory, sessions, keyframes and its chunks for which `from_newer` holds, and
/// every other chunk of `older`. What a map keeps in its .h5 (a closed map: everything) is
/// copied as stored, still compressed; what is still in its journal is encoded afresh. Both
/// maps must have nothing unflushed (std::logic_error) and the same voxel size, tau and
/// encoding (std::runtime_error naming both values); `into` must be neither of them.
/// Returns the chunks taken from each.
struct SpliceCounts {
  std::size_t from_newer = 0;
  std::size_t from_older = 0;
};
SpliceCounts splice_maps(const std::filesystem::path& into, const Hdf5ChunkStore& newer,
                         const std::function<bool(const ChunkKey&)>& from_newer,
                         const Hdf5ChunkStore& older);

class Hdf5ChunkStore final : public ChunkStore {
 public:
  /// kCreate*: `metadata` is written. kAppend: `metadata` must match the file's voxel size,
  /// tau and encoding, else std::runtime_error naming both values. kReadOnly: `metadata` is
  /// ignored. Every failure (missing, unwritable, foreign or damaged file) throws
  /// std::runtime_error with the path in the message.
  Hdf5ChunkStore(const std::filesystem::path& path, OpenMode mode, const MapMetadata& metadata,
                 const StoreSettings& settings = {});
  /// Opens an existing map read-only.
  explicit Hdf5ChunkStore(const std::filesystem::path& path, const StoreSettings& settings = {});
  /// Calls close(); errors there are swallowed (call close() to see them).
  ~Hdf5ChunkStore() override;

  Hdf5ChunkStore(const Hdf5ChunkStore&) = delete;
  Hdf5ChunkStore& operator=(const Hdf5ChunkStore&) = delete;

  std::optional<Chunk> read(const ChunkKey& key) override;
  void write(const ChunkKey& key, const Chunk& chunk) override;
  std::vector<ChunkKey> keys() const override;
  void flush() override;
  const MapMetadata& metadata() const override { return metadata_; }

  /// Replaces the stored trajectory (durable at the next flush).
  void write_trajectory(const std::vector<TrajectoryPose>& poses);
  std::vector<TrajectoryPose> read_trajectory() const { return trajectory_; }

  /// Adds keyframes, or replaces those of the same (session, index); durable at the next
  /// flush, like chunks. Every keyframe is checked first (descriptor of rows x cols values,
  /// whole points, finite stamp and pose): std::invalid_argument, and none is stored.
  void write_keyframes(const std::vector<StoredKeyframe>& keyframes);
  /// Every stored keyframe, sorted by (session, index); read from the file on each call.
  std::vector<StoredKeyframe> read_keyframes() const;
  /// One keyframe, or nothing when none has this key: for reading a large map's keyframes
  /// one at a time rather than all at once.
  std::optional<StoredKeyframe> read_keyframe(const KeyframeKey& key) const;
  /// The keys of every stored keyframe, sorted, without reading the keyframes.
  std::vector<KeyframeKey> keyframe_keys() const;
  /// Replaces the sessions table (durable at the next flush). Ids must be unique and stamps
  /// finite, else std::invalid_argument.
  void write_sessions(const std::vector<MapSession>& sessions);
  std::vector<MapSession> read_sessions() const { return sessions_; }

  /// Flushes, then writes a new .h5 holding everything, replaces the old one atomically and
  /// empties the journal.
  void checkpoint();
  /// Flushes and (per settings) checkpoints; the store is unusable afterwards.
  void close();

  const std::filesystem::path& path() const { return path_; }
  std::size_t journal_bytes() const;

 private:
  friend SpliceCounts splice_maps(const std::filesystem::path& into, const Hdf5ChunkStore& newer,
                                  const std::function<bool(const ChunkKey&)>& from_newer,
                                  const Hdf5ChunkStore& older);

  struct Location {
    bool in_journal = false;  ///< else in the .h5
    uint64_t offset = 0;      ///< of the record's payload in the journal, bytes
    uint32_t size = 0;        ///< payload size, bytes
  };
  struct CacheEntry {
    Chunk chunk;
    bool dirty = false;
    std::list<ChunkKey>::iterator lru;
  };

  void open_existing(OpenMode mode, const MapMetadata* expected);
  void require_writable(const char* what) const;
  void touch(CacheEntry& entry);
  void evict_if_needed();
  /// Appends the cached chunks of `keys` to the journal, in that order. Compression, most of
  /// the work, runs in parallel, a batch of chunks at a time.
  void journal_chunks(const std::vector<ChunkKey>& keys);
  Chunk load(const ChunkKey& key, const Location& where) const;
  StoredKeyframe load_keyframe(const KeyframeKey& key, const Location& where) const;
  /// Appends the unflushed keyframes and, when changed, the sessions table to the journal.
  void journal_keyframes_and_sessions();
  bool has_unflushed_writes() const;
  /// The journal's size beyond which a flush checkpoints (see journal_limit_bytes).
  std::size_t fold_threshold_bytes() const;
  /// Puts a durable chunk into `writer`: copied as stored from the .h5, else decoded from the
  /// journal and encoded again.
  void write_durable_chunk(detail::Hdf5MapWriter& writer, const ChunkKey& key) const;
  /// Puts the trajectory, the durable keyframes and the sessions into `writer`.
  void write_durable_records(detail::Hdf5MapWriter& writer) const;

  std::filesystem::path path_;
  StoreSettings settings_;
  MapMetadata metadata_;
  bool writable_ = false;
  bool closed_ = false;
  std::unique_ptr<detail::Hdf5MapReader> file_;
  std::unique_ptr<detail::Journal> journal_;
  std::map<ChunkKey, Location> stored_;  ///< durable chunks (journal wins over the .h5)
  std::set<ChunkKey> present_;           ///< every key holding a chunk now, durable or not
  std::unordered_map<ChunkKey, CacheEntry, ChunkKeyHash> cache_;
  std::list<ChunkKey> lru_;  ///< front = most recently used
  std::vector<TrajectoryPose> trajectory_;
  bool trajectory_dirty_ = false;
  std::map<KeyframeKey, Location> keyframes_;  ///< durable keyframes (journal wins over .h5)
  std::map<KeyframeKey, StoredKeyframe> unflushed_keyframes_;
  std::vector<MapSession> sessions_;
  bool sessions_dirty_ = false;
};

}  // namespace featsense::storage
