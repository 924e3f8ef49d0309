#pragma once
/// The local map and the global store together: the local map follows the sensor, the
/// bricks it leaves are spilled into the store's chunks and the bricks it enters are loaded
/// from them, so that the store plus the local map always hold the whole map. sync() writes
/// the local map into the store too, after which the store alone holds it.
///
/// The store keeps no partial truth: a chunk that the local map only partly covers is read,
/// its covered bricks replaced, and written back whole.

#include <cstdint>
#include <set>
#include <unordered_map>
#include <vector>

#include "featsense/storage/chunk_store.hpp"
#include "featsense/tsdf/integrator.hpp"
#include "featsense/tsdf/local_map_shift.hpp"

namespace featsense::storage {

struct ShiftingMapStats {
  size_t shifts = 0;
  size_t bricks_spilled = 0;
  size_t bricks_loaded = 0;
  size_t chunks_written = 0;    ///< chunks written to the store (spills and syncs)
  size_t chunks_unchanged = 0;  ///< chunks not written because the store already held them
  size_t syncs = 0;
};

class ShiftingMap {
 public:
  /// Takes `map` and `store` by reference (both must outlive this) and loads the local map's
  /// region from the store: a map continued from an existing store starts where it left off.
  /// The store's voxel size must be the map's.
  ShiftingMap(tsdf::Integrator& map, ChunkStore& store, double shift_threshold_m);

  /// Moves the local map onto the sensor when the sensor is more than the shift threshold
  /// from the map's centre. Returns true when it moved.
  bool follow(tsdf::Vec3 sensor_m);
  /// Moves the local map so that its lowest corner is `origin` (whole bricks). Returns true
  /// when it moved (false: it was there already).
  bool move_to(tsdf::Index3 origin);
  /// Writes the local map's observed chunks into the store (unchanged ones are skipped) and
  /// flushes the store: afterwards the store alone holds the whole map, durably.
  void sync();
  /// The whole map's voxels in the box of `dim` voxels from global voxel `origin`, x fastest
  /// (index x + dim.x * (y + dim.y * z)): from the local map where it covers them, else from
  /// the store (unobserved where neither holds them). For a preview of the map while it is
  /// made; the store is only read.
  void read_block(tsdf::Index3 origin, tsdf::Index3 dim, std::vector<uint32_t>& voxels);
  /// read_block for several boxes of one size at once: each brick is read once (one transfer
  /// from the GPU, one read of each stored chunk) however many boxes it reaches into. The
  /// vectors of `blocks` are reused where they are there already (no fresh pages to clear).
  void read_blocks(const std::vector<tsdf::Index3>& origins, tsdf::Index3 dim,
                   std::vector<std::vector<uint32_t>>& blocks);

  /// The centre of the local map, map frame, metres.
  tsdf::Vec3 centre_m() const;
  const ShiftingMapStats& stats() const { return stats_; }
  tsdf::Integrator& integrator() { return map_; }

 private:
  /// Voxels of bricks[k] start at voxels_of(k).
  template <typename VoxelsOf>
  void spill(const std::vector<tsdf::Index3>& bricks, const VoxelsOf& voxels_of);
  void load(const std::vector<tsdf::Index3>& bricks, std::vector<uint32_t>& voxels);
  /// Reads `bricks` from the local map and spills them, a batch of whole chunks at a time:
  /// never more than a batch of the map copied at once.
  void spill_from_map(const std::vector<tsdf::Index3>& bricks);
  /// The bricks of `bricks` whose chunk the store holds (`stored`, their voxels in that
  /// order) and the others (`absent`).
  void load_stored(const std::vector<tsdf::Index3>& bricks, std::vector<tsdf::Index3>& stored,
                   std::vector<uint32_t>& voxels, std::vector<tsdf::Index3>& absent);
  /// Overwrites `bricks` of the local map with unobserved voxels, a few MB at a time.
  void clear_bricks(const std::vector<tsdf::Index3>& bricks);
  bool unchanged_in_store(const ChunkKey& key, uint64_t digest) const;

  tsdf::Integrator& map_;
  ChunkStore& store_;
  double shift_threshold_m_;
  std::set<ChunkKey> keys_at_open_;                               ///< digests unknown
  std::unordered_map<ChunkKey, uint64_t, ChunkKeyHash> written_;  ///< digest of the last write
  ShiftingMapStats stats_;
  std::vector<uint32_t> slab_;         ///< bricks on their way in or out, kept between shifts
  std::vector<uint32_t> unobserved_;   ///< unobserved voxels to clear entering bricks with
  std::vector<uint32_t> read_inside_;  ///< read_blocks' bricks, kept between calls
  std::vector<uint32_t> read_outside_;
};

/// Where follow() puts a local map of `geometry` for a sensor at `sensor_m`: the origin of
/// the map centred on the sensor's brick once the sensor is more than `shift_threshold_m`
/// from the map's centre, else `geometry.origin`. A plan of where each scan's local map will
/// lie (mapping/reintegration_plan.hpp) follows the same rule.
tsdf::Index3 followed_origin(const tsdf::LocalMapGeometry& geometry, tsdf::Vec3 sensor_m,
                             double shift_threshold_m);

/// A 64-bit digest of a chunk's voxels, to tell whether a chunk changed since it was written.
uint64_t chunk_digest(const Chunk& chunk);

}  // namespace featsense::storage
