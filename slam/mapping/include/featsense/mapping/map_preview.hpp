#pragma once
// The map as it is being made, for a person watching a live run: about every interval_s the
// pass re-meshes the chunks (storage/chunk.hpp, 64^3 voxels) that scans changed since the last
// refresh and hands them over with the path so far, the latest pose and its latency. Only
// changed chunks travel, so a refresh costs what changed, not the size of the map.
//
// The union of the latest mesh of every chunk is the map's mesh (mesh/marching_cubes.hpp with
// the same min_weight), once the last refresh (at the end of the pass) is in. A chunk counts
// as changed where a scan's point lands within the truncation distance of it; a surface that
// rays carved away where no later point landed (a car that drove off) stays in the preview
// until its chunk is re-meshed for another reason.

#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/storage/chunk.hpp"

namespace featsense::mapping {

/// One chunk's part of the map's mesh (map frame): the cubes whose lowest voxel lies in the
/// chunk, with normals. Empty: the chunk holds no surface (any more).
struct ChunkMesh {
  storage::ChunkKey key;
  mesh::TriangleMesh mesh;
};

struct MapPreview {
  uint64_t refresh = 0;           ///< 1, 2, ... in the order they are handed over
  bool last = false;              ///< the pass's last refresh: every changed chunk is in
  std::vector<ChunkMesh> chunks;  ///< re-meshed since the previous refresh
  size_t chunks_waiting = 0;      ///< changed chunks left for the next refresh (a backlog)
  /// The poses made final since the previous refresh (integrated, or kept where the real-time
  /// policy skipped the integration), in order.
  slam::Trajectory new_poses;
  /// The front end's latest pose (before refinement: ahead of new_poses) and its stamp.
  Eigen::Isometry3d latest_pose = Eigen::Isometry3d::Identity();
  int64_t latest_stamp_ns = 0;
  bool has_latest_pose = false;
  /// Milliseconds from the latest scan's arrival to its pose, and from the latest integrated
  /// scan's arrival to its integration (NaN: none yet).
  double pose_latency_ms = std::nan("");
  double integration_latency_ms = std::nan("");
  size_t frames_read = 0;
  size_t frames_mapped = 0;
  size_t integrations_skipped = 0;  ///< by the real-time policy
  double meshing_ms = 0.0;          ///< wall time this refresh's meshing took
};

struct MapPreviewSettings {
  /// Seconds between refreshes (a refresh also waits for the previous one's meshing).
  double interval_s = 1.0;
  /// Chunks re-meshed per refresh at most, nearest the sensor first (the rest wait): bounds
  /// the memory in flight (1.2 MB a chunk) and the time one refresh takes.
  size_t max_chunks = 128;
  /// As mesh::MeshingSettings::min_weight.
  double min_weight = 0.5;
  /// Called from the pass's meshing thread, one refresh at a time.
  std::function<void(MapPreview)> deliver;
};

}  // namespace featsense::mapping
