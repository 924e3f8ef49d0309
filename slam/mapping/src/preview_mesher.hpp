#pragma once
// The live preview of a pass (map_preview.hpp): the integrating thread marks the chunks that
// each scan changes and, once an interval has passed and the previous refresh is meshed,
// copies the changed chunks' voxels (with the one-voxel border meshing needs); a thread of its
// own, below the mapping's priority, meshes them and hands the refresh over. The integrating
// thread thus only pays for the copies.

#include <Eigen/Geometry>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <thread>
#include <unordered_set>
#include <vector>

#include "featsense/mapping/map_preview.hpp"
#include "featsense/storage/chunk.hpp"
#include "featsense/storage/shifting_map.hpp"
#include "featsense/tsdf/local_map_geometry.hpp"
#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::mapping {

class PreviewMesher {
 public:
  PreviewMesher(MapPreviewSettings settings, double voxel_size_m, double truncation_m);
  /// Stops the meshing thread; what it was meshing is not handed over.
  ~PreviewMesher();
  PreviewMesher(const PreviewMesher&) = delete;
  PreviewMesher& operator=(const PreviewMesher&) = delete;

  /// The chunks within the truncation distance of a scan's points (and those whose cubes
  /// reach into them) have changed; points farther than that outside the local map `bounds`
  /// (whose rays are clipped to it) change nothing.
  void mark(const tsdf::RayBatch& rays, const tsdf::LocalMapGeometry& bounds);
  /// A pose made final (integrated or not).
  void add_pose(int64_t stamp_ns, const Eigen::Isometry3d& pose);

  /// Whether a refresh is due: the interval has passed and the previous one is meshed.
  bool due() const;
  /// Copies up to max_chunks changed chunks (nearest `sensor` first) out of `map` (null: no
  /// map yet, the poses only) and hands them to the meshing thread with `status` (its
  /// counts, latencies and latest pose; the rest is filled in here).
  void refresh(storage::ShiftingMap* map, const Eigen::Vector3d& sensor, MapPreview status);
  /// The end of the pass: every changed chunk meshed and handed over, the last refresh marked
  /// so; returns when it has been.
  void finish(storage::ShiftingMap* map, const Eigen::Vector3d& sensor, MapPreview status);

 private:
  struct Job {
    MapPreview preview;
    std::vector<storage::ChunkKey> keys;
    std::vector<std::vector<uint32_t>> blocks;  ///< padded, as mesh::extract_chunk_mesh reads
  };
  void mesh_jobs();
  void wait_idle();

  MapPreviewSettings settings_;
  double voxel_size_m_;
  double truncation_m_;
  std::unordered_set<storage::ChunkKey, storage::ChunkKeyHash> changed_;
  slam::Trajectory new_poses_;
  uint64_t refreshes_ = 0;
  std::chrono::steady_clock::time_point last_refresh_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Job> job_;  ///< waiting for, or being meshed by, the meshing thread
  /// Blocks meshed already, kept for the next refresh's copies: their pages are mapped.
  std::vector<std::vector<uint32_t>> spare_blocks_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace featsense::mapping
