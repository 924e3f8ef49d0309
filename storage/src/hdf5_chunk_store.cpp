#include "featsense/storage/hdf5_chunk_store.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "chunk_codec.hpp"
#include "file_ops.hpp"
#include "hdf5_map_file.hpp"
#include "journal.hpp"
#include "keyframe_records.hpp"

namespace featsense::storage {

namespace {

std::filesystem::path with_suffix(const std::filesystem::path& path, const char* suffix) {
  return std::filesystem::path(path.string() + suffix);
}

bool same_length(double a, double b) {
  // Lengths come from the same YAML text; a relative 1e-9 only forgives a decimal round trip.
  return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b));
}

std::string format_length(double metres) {
  std::ostringstream out;
  out.precision(10);  // enough to tell settings apart, short enough to read
  out << metres << " m";
  return out.str();
}

/// `what`: the action refused, with the map it names ("cannot continue the map").
void check_compatible(const MapMetadata& file, const MapMetadata& wanted,
                      const std::filesystem::path& path, const char* what) {
  std::string problems;
  if (!same_length(file.voxel_size_m, wanted.voxel_size_m))
    problems += " voxel size: map " + format_length(file.voxel_size_m) + ", this run " +
                format_length(wanted.voxel_size_m) + ";";
  if (!same_length(file.truncation_m, wanted.truncation_m))
    problems += " truncation (tau): map " + format_length(file.truncation_m) + ", this run " +
                format_length(wanted.truncation_m) + ";";
  if (file.value_scale != wanted.value_scale || file.weight_scale != wanted.weight_scale)
    problems += " voxel encoding: map value/weight scale " + std::to_string(file.value_scale) +
                "/" + std::to_string(file.weight_scale) + ", this run " +
                std::to_string(wanted.value_scale) + "/" + std::to_string(wanted.weight_scale) +
                ";";
  if (!problems.empty())
    throw std::runtime_error(std::string(what) + " " + path.string() +
                             ", its settings differ:" + problems);
}

std::vector<uint8_t> trajectory_bytes(const std::vector<TrajectoryPose>& poses) {
  std::vector<uint8_t> bytes(poses.size() * sizeof(TrajectoryPose));
  if (!bytes.empty()) std::memcpy(bytes.data(), poses.data(), bytes.size());
  return bytes;
}

}  // namespace

Hdf5ChunkStore::Hdf5ChunkStore(const std::filesystem::path& path, OpenMode mode,
                               const MapMetadata& metadata, const StoreSettings& settings)
    : path_(path), settings_(settings), metadata_(metadata) {
  if (mode == OpenMode::kAppend || mode == OpenMode::kReadOnly) {
    open_existing(mode, mode == OpenMode::kAppend ? &metadata : nullptr);
    return;
  }
  if (mode == OpenMode::kCreate && std::filesystem::exists(path))
    throw std::runtime_error("map already exists (open it to append, or overwrite it): " +
                             path.string());
  if (!(metadata.voxel_size_m > 0.0) || !(metadata.truncation_m > 0.0))
    throw std::invalid_argument("map metadata needs a positive voxel size and tau: " +
                                path.string());
  metadata_.format_version = kFormatVersion;
  metadata_.chunk_size = kChunkSize;
  writable_ = true;
  // The journal is emptied first: records of a map being overwritten must never be replayed
  // over the new one.
  journal_ = std::make_unique<detail::Journal>(with_suffix(path, ".journal"), true, true);
  const auto tmp = with_suffix(path, ".tmp");
  {
    detail::Hdf5MapWriter writer(tmp, metadata_, settings_.deflate_level);
    writer.close();
  }
  detail::replace_file(tmp, path);
  file_ = std::make_unique<detail::Hdf5MapReader>(path);
}

Hdf5ChunkStore::Hdf5ChunkStore(const std::filesystem::path& path, const StoreSettings& settings)
    : Hdf5ChunkStore(path, OpenMode::kReadOnly, MapMetadata{}, settings) {}

Hdf5ChunkStore::~Hdf5ChunkStore() {
  try {
    close();
  } catch (...) {
    // A destructor must not throw; callers that care call close() themselves.
  }
}

void Hdf5ChunkStore::open_existing(OpenMode mode, const MapMetadata* expected) {
  writable_ = mode == OpenMode::kAppend;
  file_ = std::make_unique<detail::Hdf5MapReader>(path_);
  metadata_ = file_->metadata();
  if (expected != nullptr) check_compatible(metadata_, *expected, path_, "cannot continue the map");
  for (const auto& key : file_->keys()) {
    stored_[key] = Location{};
    present_.insert(key);
  }
  trajectory_ = file_->read_trajectory();
  for (const auto& key : file_->keyframe_keys()) keyframes_[key] = Location{};
  sessions_ = file_->read_sessions();

  journal_ = std::make_unique<detail::Journal>(with_suffix(path_, ".journal"), writable_, false);
  for (const auto& record : journal_->replay()) {
    if (record.type == detail::RecordType::kTrajectory) {
      const auto bytes = journal_->read_payload(record.payload_offset, record.payload_size);
      trajectory_.resize(bytes.size() / sizeof(TrajectoryPose));
      if (!trajectory_.empty())
        std::memcpy(trajectory_.data(), bytes.data(), trajectory_.size() * sizeof(TrajectoryPose));
    } else if (record.type == detail::RecordType::kKeyframe) {
      // Keyed, not appended: records replayed again after a checkpoint that was cut short
      // before the journal was emptied replace the same keyframes.
      keyframes_[detail::keyframe_key_of_record(record.key)] =
          Location{true, record.payload_offset, record.payload_size};
    } else if (record.type == detail::RecordType::kSessions) {
      sessions_ = detail::decode_sessions(
          journal_->read_payload(record.payload_offset, record.payload_size), journal_->path());
    } else if (record.payload_size == 0) {
      stored_.erase(record.key);
      present_.erase(record.key);
    } else {
      stored_[record.key] = Location{true, record.payload_offset, record.payload_size};
      present_.insert(record.key);
    }
  }
  // A checkpoint interrupted by a crash leaves its unfinished copy behind.
  if (writable_) std::filesystem::remove(with_suffix(path_, ".tmp"));
  // An older map is rewritten in this version before anything is journalled over it: a
  // program that reads only the older version then refuses the map rather than stopping its
  // replay at the first record type it does not know.
  if (writable_ && metadata_.format_version < kFormatVersion) checkpoint();
}

void Hdf5ChunkStore::require_writable(const char* what) const {
  if (closed_) throw std::logic_error(std::string(what) + " on a closed map: " + path_.string());
  if (!writable_)
    throw std::logic_error(std::string(what) + " on a map opened read-only: " + path_.string());
}

void Hdf5ChunkStore::touch(CacheEntry& entry) { lru_.splice(lru_.begin(), lru_, entry.lru); }

Chunk Hdf5ChunkStore::load(const ChunkKey& key, const Location& where) const {
  if (!where.in_journal) return file_->read(key);
  const auto bytes =
      detail::decompress_bytes(journal_->read_payload(where.offset, where.size), kChunkBytes);
  Chunk chunk;
  std::memcpy(chunk.voxels.data(), bytes.data(), kChunkBytes);
  return chunk;
}

std::optional<Chunk> Hdf5ChunkStore::read(const ChunkKey& key) {
  if (closed_) throw std::logic_error("read on a closed map: " + path_.string());
  if (present_.count(key) == 0) return std::nullopt;
  if (auto it = cache_.find(key); it != cache_.end()) {
    touch(it->second);
    return it->second.chunk;
  }
  Chunk chunk = load(key, stored_.at(key));
  lru_.push_front(key);
  cache_.emplace(key, CacheEntry{chunk, false, lru_.begin()});
  evict_if_needed();
  return chunk;
}

void Hdf5ChunkStore::write(const ChunkKey& key, const Chunk& chunk) {
  require_writable("write");
  if (chunk.voxels.size() != kChunkVoxels)
    throw std::invalid_argument("a chunk holds 64^3 voxels, got " +
                                std::to_string(chunk.voxels.size()));
  auto it = cache_.find(key);
  if (is_empty(chunk)) {
    present_.erase(key);
    if (stored_.count(key) == 0) {
      // Never durable: nothing to remove on disk.
      if (it != cache_.end()) {
        lru_.erase(it->second.lru);
        cache_.erase(it);
      }
      return;
    }
  } else {
    present_.insert(key);
  }
  if (it == cache_.end()) {
    lru_.push_front(key);
    cache_.emplace(key, CacheEntry{chunk, true, lru_.begin()});
  } else {
    it->second.chunk = chunk;
    it->second.dirty = true;
    touch(it->second);
  }
  evict_if_needed();
}

void Hdf5ChunkStore::evict_if_needed() {
  const std::size_t capacity = std::max<std::size_t>(1, settings_.cache_bytes / kChunkBytes);
  if (cache_.size() <= capacity) return;
  // Evicting a dirty chunk compresses it: several at once are compressed in parallel, so
  // the cache is emptied down to an eighth below its limit (at most 16 chunks below).
  const std::size_t batch = std::clamp<std::size_t>(capacity / 8, 1, 16);
  const std::size_t target = capacity + 1 - batch;
  std::vector<ChunkKey> victims;
  for (auto it = lru_.rbegin(); it != lru_.rend() && cache_.size() - victims.size() > target;
       ++it) {
    victims.push_back(*it);
  }
  std::vector<ChunkKey> dirty;
  for (const ChunkKey& key : victims)
    if (cache_.at(key).dirty) dirty.push_back(key);
  journal_chunks(dirty);
  for (const ChunkKey& key : victims) {
    lru_.erase(cache_.at(key).lru);
    cache_.erase(key);
  }
}

void Hdf5ChunkStore::journal_chunks(const std::vector<ChunkKey>& keys) {
  constexpr size_t kBatch = 32;
  for (size_t first = 0; first < keys.size(); first += kBatch) {
    const size_t count = std::min(kBatch, keys.size() - first);
    // An empty payload records a chunk that holds nothing any more.
    std::vector<std::vector<uint8_t>> payloads(count);
    tbb::parallel_for(size_t{0}, count, [&](size_t k) {
      const Chunk& chunk = cache_.at(keys[first + k]).chunk;
      if (!is_empty(chunk)) {
        payloads[k] = detail::compress_bytes(reinterpret_cast<const uint8_t*>(chunk.voxels.data()),
                                             kChunkBytes, settings_.deflate_level);
      }
    });
    for (size_t k = 0; k < count; ++k) {
      const ChunkKey& key = keys[first + k];
      const uint64_t offset = journal_->append(detail::RecordType::kChunk, key, payloads[k]);
      if (payloads[k].empty()) {
        stored_.erase(key);
      } else {
        stored_[key] = Location{true, offset, static_cast<uint32_t>(payloads[k].size())};
      }
    }
  }
}

std::vector<ChunkKey> Hdf5ChunkStore::keys() const {
  return std::vector<ChunkKey>(present_.begin(), present_.end());
}

void Hdf5ChunkStore::write_trajectory(const std::vector<TrajectoryPose>& poses) {
  require_writable("write_trajectory");
  trajectory_ = poses;
  trajectory_dirty_ = true;
}

void Hdf5ChunkStore::write_keyframes(const std::vector<StoredKeyframe>& keyframes) {
  require_writable("write_keyframes");
  for (const StoredKeyframe& keyframe : keyframes) detail::check_keyframe(keyframe, path_);
  for (const StoredKeyframe& keyframe : keyframes) unflushed_keyframes_[keyframe.key()] = keyframe;
}

std::vector<KeyframeKey> Hdf5ChunkStore::keyframe_keys() const {
  std::set<KeyframeKey> keys;
  for (const auto& [key, where] : keyframes_) keys.insert(key);
  for (const auto& [key, keyframe] : unflushed_keyframes_) keys.insert(key);
  return std::vector<KeyframeKey>(keys.begin(), keys.end());
}

std::vector<StoredKeyframe> Hdf5ChunkStore::read_keyframes() const {
  std::vector<StoredKeyframe> keyframes;
  for (const KeyframeKey& key : keyframe_keys()) keyframes.push_back(*read_keyframe(key));
  return keyframes;
}

std::optional<StoredKeyframe> Hdf5ChunkStore::read_keyframe(const KeyframeKey& key) const {
  if (closed_) throw std::logic_error("read_keyframe on a closed map: " + path_.string());
  if (const auto it = unflushed_keyframes_.find(key); it != unflushed_keyframes_.end())
    return it->second;
  if (const auto it = keyframes_.find(key); it != keyframes_.end())
    return load_keyframe(key, it->second);
  return std::nullopt;
}

StoredKeyframe Hdf5ChunkStore::load_keyframe(const KeyframeKey& key, const Location& where) const {
  if (!where.in_journal) return file_->read_keyframe(key);
  StoredKeyframe keyframe =
      detail::decode_keyframe(journal_->read_payload(where.offset, where.size), journal_->path());
  if (!(keyframe.key() == key))
    throw std::runtime_error("damaged keyframe record in " + journal_->path().string());
  return keyframe;
}

void Hdf5ChunkStore::write_sessions(const std::vector<MapSession>& sessions) {
  require_writable("write_sessions");
  detail::check_sessions(sessions, path_);
  sessions_ = sessions;
  std::sort(sessions_.begin(), sessions_.end(),
            [](const MapSession& a, const MapSession& b) { return a.id < b.id; });
  sessions_dirty_ = true;
}

void Hdf5ChunkStore::journal_keyframes_and_sessions() {
  for (auto it = unflushed_keyframes_.begin(); it != unflushed_keyframes_.end();) {
    const auto payload = detail::encode_keyframe(it->second);
    const uint64_t offset =
        journal_->append(detail::RecordType::kKeyframe, detail::record_key_of(it->first), payload);
    keyframes_[it->first] = Location{true, offset, static_cast<uint32_t>(payload.size())};
    // Erased one by one: after a failed append the rest stay unflushed, as dirty chunks do.
    it = unflushed_keyframes_.erase(it);
  }
  if (sessions_dirty_) {
    journal_->append(detail::RecordType::kSessions, {}, detail::encode_sessions(sessions_));
    sessions_dirty_ = false;
  }
}

bool Hdf5ChunkStore::has_unflushed_writes() const {
  return trajectory_dirty_ || sessions_dirty_ || !unflushed_keyframes_.empty() ||
         std::any_of(cache_.begin(), cache_.end(), [](const auto& kv) { return kv.second.dirty; });
}

void Hdf5ChunkStore::flush() {
  if (closed_ || !writable_) return;
  std::vector<ChunkKey> dirty;
  for (const auto& [key, entry] : cache_)
    if (entry.dirty) dirty.push_back(key);
  std::sort(dirty.begin(), dirty.end());
  journal_chunks(dirty);
  for (const ChunkKey& key : dirty) cache_.at(key).dirty = false;
  if (trajectory_dirty_) {
    journal_->append(detail::RecordType::kTrajectory, {}, trajectory_bytes(trajectory_));
    trajectory_dirty_ = false;
  }
  journal_keyframes_and_sessions();
  journal_->sync();
  if (journal_->size_bytes() > fold_threshold_bytes()) checkpoint();
}

std::size_t Hdf5ChunkStore::fold_threshold_bytes() const {
  std::error_code error;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path_, error);
  const std::size_t half_file = error ? 0 : static_cast<std::size_t>(file_bytes / 2);
  return std::max(settings_.journal_limit_bytes, half_file);
}

void Hdf5ChunkStore::checkpoint() {
  require_writable("checkpoint");
  if (has_unflushed_writes()) {
    // Only the journal and the old file are copied below, so everything must be in them.
    const std::size_t limit = settings_.journal_limit_bytes;
    settings_.journal_limit_bytes = SIZE_MAX;
    try {
      flush();
    } catch (...) {
      settings_.journal_limit_bytes = limit;
      throw;
    }
    settings_.journal_limit_bytes = limit;
  }
  const auto tmp = with_suffix(path_, ".tmp");
  try {
    detail::Hdf5MapWriter writer(tmp, metadata_, settings_.deflate_level);
    for (const auto& key : present_) write_durable_chunk(writer, key);
    write_durable_records(writer);
    writer.close();
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
  // From here a crash leaves either the old file with the whole journal, or the new file
  // with a journal whose records it already holds: replaying them again changes nothing.
  detail::replace_file(tmp, path_);
  file_ = std::make_unique<detail::Hdf5MapReader>(path_);
  journal_->reset();
  for (auto& [key, where] : stored_) where = Location{};
  for (auto& [key, where] : keyframes_) where = Location{};
  metadata_.format_version = kFormatVersion;
}

void Hdf5ChunkStore::write_durable_chunk(detail::Hdf5MapWriter& writer, const ChunkKey& key) const {
  const Location& where = stored_.at(key);
  if (where.in_journal)
    writer.write_chunk(key, load(key, where));
  else
    writer.copy_chunk(*file_, key);
}

void Hdf5ChunkStore::write_durable_records(detail::Hdf5MapWriter& writer) const {
  writer.write_trajectory(trajectory_);
  for (const auto& [key, where] : keyframes_) {
    if (where.in_journal)
      writer.write_keyframe(load_keyframe(key, where));
    else
      writer.copy_keyframe(*file_, key);
  }
  writer.write_sessions(sessions_);
}

SpliceCounts splice_maps(const std::filesystem::path& into, const Hdf5ChunkStore& newer,
                         const std::function<bool(const ChunkKey&)>& from_newer,
                         const Hdf5ChunkStore& older) {
  for (const Hdf5ChunkStore* map : {&newer, &older}) {
    if (map->closed_) throw std::logic_error("splicing a closed map: " + map->path_.string());
    if (map->has_unflushed_writes())
      throw std::logic_error("splicing a map with unflushed writes: " + map->path_.string());
    if (std::filesystem::exists(into) && std::filesystem::equivalent(into, map->path_))
      throw std::invalid_argument("a spliced map cannot replace one of its sources: " +
                                  into.string());
  }
  check_compatible(older.metadata_, newer.metadata_, older.path_, "cannot splice the map");
  const auto tmp = with_suffix(into, ".tmp");
  SpliceCounts counts;
  try {
    detail::Hdf5MapWriter writer(tmp, newer.metadata_, newer.settings_.deflate_level);
    for (const ChunkKey& key : newer.present_) {
      if (!from_newer(key)) continue;
      newer.write_durable_chunk(writer, key);
      ++counts.from_newer;
    }
    for (const ChunkKey& key : older.present_) {
      if (from_newer(key)) continue;
      older.write_durable_chunk(writer, key);
      ++counts.from_older;
    }
    newer.write_durable_records(writer);
    writer.close();
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
  // A journal left by an earlier map at `into` would be replayed over this one.
  std::filesystem::remove(with_suffix(into, ".journal"));
  detail::replace_file(tmp, into);
  return counts;
}

void Hdf5ChunkStore::close() {
  if (closed_) return;
  if (writable_) {
    flush();
    if (settings_.checkpoint_on_close) checkpoint();
  }
  closed_ = true;
  cache_.clear();
  lru_.clear();
  journal_.reset();
  file_.reset();
}

std::size_t Hdf5ChunkStore::journal_bytes() const {
  return journal_ ? static_cast<std::size_t>(journal_->size_bytes()) : 0;
}

}  // namespace featsense::storage
