#pragma once
// A saved map as a later session sees it: its sessions, each with its slice of the stored
// trajectory and its keyframes, ready for relocalization and for the links between sessions.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/loops/map_keyframe.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"

namespace featsense::mapping {

struct SavedSession {
  storage::MapSession session;
  /// Its scans' poses in the map frame; empty where the stored trajectory does not split into
  /// the sessions (a map made before sessions were kept).
  slam::Trajectory poses;
};

struct SavedMap {
  std::filesystem::path path;
  storage::MapMetadata metadata;
  std::vector<SavedSession> sessions;
  /// Every session's keyframes, by session then index, travelled_m along its session's path.
  std::vector<slam::loops::MapKeyframe> keyframes;
  size_t scans = 0;  ///< poses in the stored trajectory
};

/// Reads the sessions, trajectory and keyframes of the map at `path` (read-only: the file is
/// not changed). Throws std::runtime_error naming the file.
SavedMap read_saved_map(const std::filesystem::path& path);

/// A map file's keyframe as the loop closure and relocalization use it.
slam::loops::MapKeyframe map_keyframe(const storage::StoredKeyframe& stored);

/// The keyframe as a map file records it again, at `T_map_sensor`.
slam::loops::KeyframeRecord keyframe_record(const slam::loops::MapKeyframe& keyframe,
                                            const Eigen::Isometry3d& T_map_sensor);

/// Distance along `path` at each pose, from 0.
std::vector<double> travelled_along(const slam::Trajectory& path);

/// Each keyframe's travelled_m from the pose of `path` at its stamp (the nearest); keyframes
/// outside the path keep theirs.
void travelled_along_path(std::vector<slam::loops::MapKeyframe>& keyframes, size_t first,
                          size_t end, const slam::Trajectory& path);

/// Every pose of `path` moved rigidly by `T` (T * pose).
slam::Trajectory moved_by(const Eigen::Isometry3d& T, const slam::Trajectory& path);

/// `path` moved by the keyframes' moves (each keyframe's pose `before` -> `after`), spread
/// between keyframes by the distance travelled (trajectory_correction.hpp).
slam::Trajectory moved_path(const slam::Trajectory& path,
                            const std::vector<slam::loops::MapKeyframe>& keyframes, size_t first,
                            size_t end, const std::vector<Eigen::Isometry3d>& after);

}  // namespace featsense::mapping
