#pragma once
// Which scans of a map's sessions must be integrated again after their poses were corrected
// (links to a new session, a merge), and which chunks of the map before that changes. A TSDF
// voxel is a function of the scans that reached it, in order; a scan reaches only the voxels of
// its local map. So where no scan that reached a chunk moved, the chunk stays as it was, and a
// chunk that a moved scan reached (before or after) is made again from every scan that reaches
// it, in order, each with the local map where a full re-map would have put it.
//
// The rule, exactly:
// - A scan's reach: before, the box around its old position of half the local map's extent
//   plus the shift threshold plus a brick (its local map lay within it wherever the map had
//   followed the sensor to); after, its local map as a full re-map places it (the map of a
//   session starts centred on its first scan and follows the sensor by followed_origin()).
//   Both as the chunks they overlap.
// - A scan moved when its pose or a neighbour's (the poses its sweep is deskewed by) moves a
//   corner of its reach by more than a quarter voxel. Every scan of a session with no poses
//   before (a new one, or one whose scans do not match) moved.
// - The changed chunks: those a moved scan reaches, before or after.
// - The scans integrated again: every scan whose reach after meets a changed chunk.
// The map after takes the changed chunks from the scans integrated again and every other chunk
// byte for byte from the map before.

#include <Eigen/Geometry>

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <unordered_set>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/storage/chunk.hpp"
#include "featsense/storage/chunk_store.hpp"
#include "featsense/tsdf/vec3.hpp"

namespace featsense::mapping {

/// One session's scans, by stamp, with their poses before (empty: a session new to the map,
/// or one whose map before is not known scan by scan) and after.
struct SessionPoses {
  slam::Trajectory before;
  slam::Trajectory after;
};

/// The scans of one session to integrate again: stamp -> the local map's lowest corner (global
/// voxel index) as a full re-map would have it when it integrates that scan. A scan not in it
/// keeps its pose only.
struct ScanReintegration {
  /// By the stamps of the poses planned from, which the map stores as seconds in a double.
  std::map<int64_t, tsdf::Index3> origins;

  /// The local map for the scan stamped `stamp_ns` (the recording's own stamp, which the
  /// planned one matches within storage::kStoredStampToleranceNs); nothing where that scan is
  /// not to be integrated again.
  std::optional<tsdf::Index3> origin_at(int64_t stamp_ns) const;
};

using ChunkSet = std::unordered_set<storage::ChunkKey, storage::ChunkKeyHash>;

struct ReintegrationPlan {
  std::vector<ScanReintegration> sessions;  ///< one per session given, in order
  ChunkSet changed;
  size_t scans = 0;
  size_t scans_moved = 0;
  size_t scans_reintegrated = 0;
};

/// Local map settings that bound where the map before was written: its extent and shift
/// threshold (the largest of this run's and the map's own; a map keeps its voxel size).
struct LocalMapReach {
  std::array<double, 3> size_m = {40.0, 40.0, 15.0};
  double shift_threshold_m = 3.0;
};

/// The point the local map follows: the sensor's position, as the TSDF's floats.
tsdf::Vec3 local_map_anchor(const Eigen::Isometry3d& T_map_sensor);

/// This run's local map (`after`) and the largest extent and threshold of it and the map
/// before's (`before`, from its metadata's configuration).
LocalMapReach reach_before(const config::MapConfig& after, const config::MapConfig& before);

/// The plan for `sessions` (in the order they are integrated), the map after made with `after`
/// (voxel size, local map size, shift threshold), the map before bounded by `before`.
ReintegrationPlan plan_reintegration(const std::vector<SessionPoses>& sessions,
                                     const config::MapConfig& after, const LocalMapReach& before);

}  // namespace featsense::mapping
