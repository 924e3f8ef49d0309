#include "featsense/storage/shifting_map.hpp"

#include "featsense/tsdf/voxel.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>

namespace featsense::storage {
namespace {

using tsdf::Index3;
using tsdf::kBrickSize;
using tsdf::kBrickVoxels;

constexpr int32_t kBricksPerChunk = kChunkSize / kBrickSize;  // per axis
constexpr size_t kBricksInChunk =
    static_cast<size_t>(kBricksPerChunk) * kBricksPerChunk * kBricksPerChunk;
/// Chunks assembled or taken apart at once (1 MB each): enough to keep the cores busy, few
/// enough that a sync of the whole local map needs little memory beyond it.
constexpr size_t kChunksPerBatch = 32;

ChunkKey chunk_of_brick(Index3 brick) {
  return chunk_of_voxel(static_cast<int64_t>(brick.x) * kBrickSize,
                        static_cast<int64_t>(brick.y) * kBrickSize,
                        static_cast<int64_t>(brick.z) * kBrickSize);
}

/// The lowest voxel of `brick` in chunk-local coordinates (0..63).
Index3 brick_corner_in_chunk(Index3 brick, const ChunkKey& key) {
  return {brick.x * kBrickSize - key.x * kChunkSize, brick.y * kBrickSize - key.y * kChunkSize,
          brick.z * kBrickSize - key.z * kChunkSize};
}

/// The voxels of a batch of chunks (32 MB at most) or of the stored bricks that enter the
/// local map: kept from one shift to the next up to this size, so that its pages are not
/// faulted in and cleared each time.
constexpr size_t kSlabKeptVoxels = kChunksPerBatch * kChunkVoxels;

/// The bricks of one chunk: indices into the list of bricks.
struct ChunkGroup {
  ChunkKey key;
  std::vector<size_t> members;
};

/// The indices into `bricks` grouped by the chunk that holds each brick, chunks in key order
/// (so that the store is written in a reproducible order).
std::vector<ChunkGroup> group_by_chunk(const std::vector<Index3>& bricks) {
  std::map<ChunkKey, std::vector<size_t>> groups;
  for (size_t k = 0; k < bricks.size(); ++k) groups[chunk_of_brick(bricks[k])].push_back(k);
  std::vector<ChunkGroup> ordered;
  ordered.reserve(groups.size());
  for (auto& [key, members] : groups) ordered.push_back({key, std::move(members)});
  return ordered;
}

/// Calls work(first, count) for consecutive batches of kChunksPerBatch groups.
template <typename Work>
void for_each_batch(const std::vector<ChunkGroup>& groups, const Work& work) {
  for (size_t first = 0; first < groups.size(); first += kChunksPerBatch) {
    work(first, std::min(kChunksPerBatch, groups.size() - first));
  }
}

/// Brick order ((z * 8 + y) * 8 + x) into the chunk's x-fastest rows, and back.
void copy_brick_into_chunk(const uint32_t* brick_voxels, Index3 corner, Chunk& chunk) {
  for (int32_t z = 0; z < kBrickSize; ++z) {
    for (int32_t y = 0; y < kBrickSize; ++y) {
      const uint32_t* row = brick_voxels + (z * kBrickSize + y) * kBrickSize;
      std::copy_n(row, kBrickSize, &chunk.at(corner.x, corner.y + y, corner.z + z));
    }
  }
}

void copy_brick_from_chunk(const Chunk& chunk, Index3 corner, uint32_t* brick_voxels) {
  for (int32_t z = 0; z < kBrickSize; ++z) {
    for (int32_t y = 0; y < kBrickSize; ++y) {
      const uint32_t* row =
          chunk.voxels.data() + Chunk::index(corner.x, corner.y + y, corner.z + z);
      std::copy_n(row, kBrickSize, brick_voxels + (z * kBrickSize + y) * kBrickSize);
    }
  }
}

/// Calls f(brick) for every brick that the box of `dim` voxels from global voxel `origin`
/// reaches into, x fastest.
template <typename F>
void for_each_brick_in_box(Index3 origin, Index3 dim, const F& f) {
  for (int32_t z = tsdf::brick_of(origin.z); z <= tsdf::brick_of(origin.z + dim.z - 1); ++z)
    for (int32_t y = tsdf::brick_of(origin.y); y <= tsdf::brick_of(origin.y + dim.y - 1); ++y)
      for (int32_t x = tsdf::brick_of(origin.x); x <= tsdf::brick_of(origin.x + dim.x - 1); ++x)
        f(Index3{x, y, z});
}

/// Copies the voxels of `brick` (brick order) that lie in the block of `dim` voxels from global
/// voxel `origin` into the block's x-fastest array, a row of up to 8 voxels at a time.
void copy_brick_into_block(const uint32_t* brick_voxels, Index3 brick, Index3 origin, Index3 dim,
                           std::vector<uint32_t>& block) {
  const Index3 first = tsdf::LocalMapGeometry::first_voxel_of_brick(brick);
  const int32_t x_begin = std::max(0, origin.x - first.x);
  const int32_t x_end = std::min(kBrickSize, origin.x + dim.x - first.x);
  if (x_begin >= x_end) return;
  for (int32_t z = 0; z < kBrickSize; ++z) {
    const int32_t bz = first.z + z - origin.z;
    if (bz < 0 || bz >= dim.z) continue;
    for (int32_t y = 0; y < kBrickSize; ++y) {
      const int32_t by = first.y + y - origin.y;
      if (by < 0 || by >= dim.y) continue;
      const size_t row =
          static_cast<size_t>(first.x + x_begin - origin.x) +
          static_cast<size_t>(dim.x) *
              (static_cast<size_t>(by) + static_cast<size_t>(dim.y) * static_cast<size_t>(bz));
      std::copy_n(brick_voxels + (z * kBrickSize + y) * kBrickSize + x_begin, x_end - x_begin,
                  block.data() + row);
    }
  }
}

}  // namespace

uint64_t chunk_digest(const Chunk& chunk) {
  // Two voxels per step, multiply-rotate mixing: fast, and a changed voxel changes the
  // digest except with probability 2^-64.
  uint64_t h = 0x9E3779B97F4A7C15ull;
  const size_t n = chunk.voxels.size();
  for (size_t i = 0; i + 1 < n; i += 2) {
    const uint64_t word =
        static_cast<uint64_t>(chunk.voxels[i]) | (static_cast<uint64_t>(chunk.voxels[i + 1]) << 32);
    h = (h ^ word) * 0xFF51AFD7ED558CCDull;
    h = (h << 29) | (h >> 35);
  }
  return h ^ (h >> 31);
}

namespace {

/// The digest of a chunk with nothing observed: what the store holds where it holds nothing.
uint64_t empty_chunk_digest() {
  static const uint64_t digest = chunk_digest(Chunk{});
  return digest;
}

}  // namespace

ShiftingMap::ShiftingMap(tsdf::Integrator& map, ChunkStore& store, double shift_threshold_m)
    : map_(map), store_(store), shift_threshold_m_(shift_threshold_m) {
  const double map_voxel = map_.geometry().voxel_size_m;
  const double store_voxel = store_.metadata().voxel_size_m;
  if (std::abs(map_voxel - store_voxel) > 1e-6 * store_voxel) {
    throw std::invalid_argument("the local map's voxel size " + std::to_string(map_voxel) +
                                " m differs from the store's " + std::to_string(store_voxel) +
                                " m");
  }
  for (const ChunkKey& key : store_.keys()) keys_at_open_.insert(key);
  if (!keys_at_open_.empty()) {
    const std::vector<Index3> bricks = tsdf::bricks_of(map_.geometry());
    std::vector<uint32_t> voxels;
    load(bricks, voxels);
    map_.write_bricks(bricks, voxels);
    stats_.bricks_loaded += bricks.size();
  }
}

namespace {

tsdf::Vec3 centre_of(const tsdf::LocalMapGeometry& geometry) {
  return 0.5f * (geometry.min_corner() + geometry.max_corner());
}

}  // namespace

tsdf::Vec3 ShiftingMap::centre_m() const { return centre_of(map_.geometry()); }

tsdf::Index3 followed_origin(const tsdf::LocalMapGeometry& geometry, tsdf::Vec3 sensor_m,
                             double shift_threshold_m) {
  if (tsdf::norm(sensor_m - centre_of(geometry)) <= shift_threshold_m) return geometry.origin;
  return tsdf::centred_origin(geometry, sensor_m);
}

bool ShiftingMap::follow(tsdf::Vec3 sensor_m) {
  return move_to(followed_origin(map_.geometry(), sensor_m, shift_threshold_m_));
}

bool ShiftingMap::move_to(Index3 origin) {
  const Index3 now = map_.geometry().origin;
  if (origin.x == now.x && origin.y == now.y && origin.z == now.z) return false;
  tsdf::LocalMapGeometry target = map_.geometry();
  target.origin = origin;
  const tsdf::BrickExchange exchange = tsdf::exchanged_bricks(map_.geometry(), target);
  // The bricks that leave go into the store first, a few chunks at a time, while the map
  // still holds them: a failing write leaves the map whole where it was. (A chunk that holds
  // both leaving and entering bricks is read back below with the leaving ones merged in;
  // the entering ones' part of it is the store's either way.)
  spill_from_map(exchange.leaving);
  // The entering bricks the store holds are read before the map moves, so that a failing
  // read leaves it unmoved too. Outside the places mapped before that is none of them.
  std::vector<Index3> stored;
  std::vector<Index3> unobserved;
  load_stored(exchange.entering, stored, slab_, unobserved);
  map_.set_origin(origin);
  map_.write_bricks(stored, slab_);
  if (slab_.size() > kSlabKeptVoxels) std::vector<uint32_t>().swap(slab_);
  clear_bricks(unobserved);
  ++stats_.shifts;
  stats_.bricks_spilled += exchange.leaving.size();
  stats_.bricks_loaded += exchange.entering.size();
  return true;
}

void ShiftingMap::sync() {
  spill_from_map(tsdf::bricks_of(map_.geometry()));
  store_.flush();
  ++stats_.syncs;
}

void ShiftingMap::spill_from_map(const std::vector<Index3>& bricks) {
  const std::vector<ChunkGroup> groups = group_by_chunk(bricks);
  std::vector<Index3> batch;
  for_each_batch(groups, [&](size_t first, size_t count) {
    batch.clear();
    for (size_t i = first; i < first + count; ++i)
      for (const size_t k : groups[i].members) batch.push_back(bricks[k]);
    map_.read_bricks(batch, slab_);
    spill(batch, [&](size_t k) { return slab_.data() + k * kBrickVoxels; });
  });
}

void ShiftingMap::load_stored(const std::vector<Index3>& bricks, std::vector<Index3>& stored,
                              std::vector<uint32_t>& voxels, std::vector<Index3>& absent) {
  stored.clear();
  absent.clear();
  voxels.clear();
  const std::vector<ChunkGroup> groups = group_by_chunk(bricks);
  for_each_batch(groups, [&](size_t first, size_t count) {
    std::vector<std::optional<Chunk>> chunks(count);
    std::vector<size_t> start(count);  // of each chunk's bricks in `stored`
    for (size_t i = 0; i < count; ++i) {
      chunks[i] = store_.read(groups[first + i].key);
      start[i] = stored.size();
      for (const size_t k : groups[first + i].members)
        (chunks[i] ? stored : absent).push_back(bricks[k]);
    }
    voxels.resize(stored.size() * kBrickVoxels);
    tbb::parallel_for(size_t{0}, count, [&](size_t i) {
      if (!chunks[i]) return;
      const ChunkGroup& group = groups[first + i];
      for (size_t m = 0; m < group.members.size(); ++m) {
        const Index3 brick = bricks[group.members[m]];
        copy_brick_from_chunk(*chunks[i], brick_corner_in_chunk(brick, group.key),
                              voxels.data() + (start[i] + m) * kBrickVoxels);
      }
    });
  });
}

void ShiftingMap::clear_bricks(const std::vector<Index3>& bricks) {
  constexpr size_t kBricksPerWrite = 4096;  // 8 MB of unobserved voxels
  std::vector<Index3> batch;
  for (size_t first = 0; first < bricks.size(); first += kBricksPerWrite) {
    const size_t count = std::min(kBricksPerWrite, bricks.size() - first);
    batch.assign(bricks.begin() + static_cast<std::ptrdiff_t>(first),
                 bricks.begin() + static_cast<std::ptrdiff_t>(first + count));
    unobserved_.resize(count * kBrickVoxels, tsdf::kUnobservedVoxel);  // all unobserved
    map_.write_bricks(batch, unobserved_);
  }
}

void ShiftingMap::read_block(Index3 origin, Index3 dim, std::vector<uint32_t>& voxels) {
  std::vector<std::vector<uint32_t>> blocks;
  read_blocks({origin}, dim, blocks);
  voxels = std::move(blocks.front());
}

void ShiftingMap::read_blocks(const std::vector<Index3>& origins, Index3 dim,
                              std::vector<std::vector<uint32_t>>& blocks) {
  if (dim.x <= 0 || dim.y <= 0 || dim.z <= 0) throw std::invalid_argument("read_block: empty box");
  // Every brick any box reaches into, once, in a fixed order.
  std::vector<Index3> bricks;
  for (const Index3& origin : origins)
    for_each_brick_in_box(origin, dim, [&](Index3 b) { bricks.push_back(b); });
  const auto brick_less = [](const Index3& a, const Index3& b) {
    return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x);
  };
  std::sort(bricks.begin(), bricks.end(), brick_less);
  bricks.erase(std::unique(bricks.begin(), bricks.end(),
                           [](const Index3& a, const Index3& b) {
                             return a.x == b.x && a.y == b.y && a.z == b.z;
                           }),
               bricks.end());
  // Bricks lie wholly inside the local map or wholly outside it (both are whole bricks): the
  // first from the integrator in one transfer, the others from the store.
  const tsdf::LocalMapGeometry& geometry = map_.geometry();
  std::vector<Index3> inside;
  std::vector<Index3> outside;
  for (const Index3& b : bricks) (geometry.contains_brick(b) ? inside : outside).push_back(b);
  std::vector<uint32_t>& inside_voxels = read_inside_;
  std::vector<uint32_t>& outside_voxels = read_outside_;
  if (!inside.empty()) map_.read_bricks(inside, inside_voxels);
  if (!outside.empty()) load(outside, outside_voxels);
  const auto voxels_of = [&](const Index3& b) -> const uint32_t* {
    const bool in = geometry.contains_brick(b);
    const std::vector<Index3>& list = in ? inside : outside;
    const size_t k = static_cast<size_t>(std::lower_bound(list.begin(), list.end(), b, brick_less) -
                                         list.begin());
    return (in ? inside_voxels : outside_voxels).data() + k * kBrickVoxels;
  };
  const size_t voxel_count =
      static_cast<size_t>(dim.x) * static_cast<size_t>(dim.y) * static_cast<size_t>(dim.z);
  blocks.resize(origins.size());
  tbb::parallel_for(size_t{0}, origins.size(), [&](size_t i) {
    const Index3 origin = origins[i];
    std::vector<uint32_t>& block = blocks[i];
    block.assign(voxel_count, tsdf::kUnobservedVoxel);
    for_each_brick_in_box(
        origin, dim, [&](Index3 b) { copy_brick_into_block(voxels_of(b), b, origin, dim, block); });
  });
}

template <typename VoxelsOf>
void ShiftingMap::spill(const std::vector<Index3>& bricks, const VoxelsOf& voxels_of) {
  const std::vector<ChunkGroup> groups = group_by_chunk(bricks);
  for_each_batch(groups, [&](size_t first, size_t count) {
    // The store is used by this thread alone: it reads the chunks that the bricks cover only
    // in part (the rest of such a chunk is kept) ...
    std::vector<std::optional<Chunk>> chunks(count);
    for (size_t i = 0; i < count; ++i) {
      const ChunkGroup& group = groups[first + i];
      if (group.members.size() < kBricksInChunk) {
        std::optional<Chunk> stored = store_.read(group.key);
        chunks[i] = stored ? std::move(stored) : Chunk{};
      }
    }
    // ... the chunks are assembled and digested in parallel ...
    std::vector<uint64_t> digests(count);
    tbb::parallel_for(size_t{0}, count, [&](size_t i) {
      const ChunkGroup& group = groups[first + i];
      if (!chunks[i]) {
        // Most of a local map is never observed: a whole chunk of such bricks where the store
        // holds nothing needs neither assembling nor writing.
        const bool unobserved =
            std::all_of(group.members.begin(), group.members.end(), [&](size_t k) {
              const uint32_t* voxels = voxels_of(k);
              return std::all_of(voxels, voxels + kBrickVoxels,
                                 [](uint32_t v) { return tsdf::unpack(v).weight == 0; });
            });
        if (unobserved && unchanged_in_store(group.key, empty_chunk_digest())) {
          digests[i] = empty_chunk_digest();
          return;
        }
        chunks[i] = Chunk{};
      }
      for (const size_t k : group.members) {
        copy_brick_into_chunk(voxels_of(k), brick_corner_in_chunk(bricks[k], group.key),
                              *chunks[i]);
      }
      digests[i] = chunk_digest(*chunks[i]);
    });
    // ... and those that changed are written, in key order.
    for (size_t i = 0; i < count; ++i) {
      const ChunkKey& key = groups[first + i].key;
      if (unchanged_in_store(key, digests[i])) {
        ++stats_.chunks_unchanged;
        continue;
      }
      store_.write(key, *chunks[i]);
      written_[key] = digests[i];
      ++stats_.chunks_written;
    }
  });
}

bool ShiftingMap::unchanged_in_store(const ChunkKey& key, uint64_t digest) const {
  const auto found = written_.find(key);
  if (found != written_.end()) return found->second == digest;
  // Never written by this map: the store holds nothing there unless it did at open (whose
  // contents are unknown here), and nothing is what an empty chunk means.
  return keys_at_open_.count(key) == 0 && digest == empty_chunk_digest();
}

void ShiftingMap::load(const std::vector<Index3>& bricks, std::vector<uint32_t>& voxels) {
  voxels.assign(bricks.size() * kBrickVoxels, tsdf::kUnobservedVoxel);
  const std::vector<ChunkGroup> groups = group_by_chunk(bricks);
  for_each_batch(groups, [&](size_t first, size_t count) {
    std::vector<std::optional<Chunk>> chunks(count);
    for (size_t i = 0; i < count; ++i) chunks[i] = store_.read(groups[first + i].key);
    tbb::parallel_for(size_t{0}, count, [&](size_t i) {
      if (!chunks[i]) return;
      const ChunkGroup& group = groups[first + i];
      for (const size_t k : group.members) {
        copy_brick_from_chunk(*chunks[i], brick_corner_in_chunk(bricks[k], group.key),
                              voxels.data() + k * kBrickVoxels);
      }
    });
  });
}

}  // namespace featsense::storage
