#include "featsense/mapping/saved_map.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "featsense/mapping/map_store.hpp"
#include "featsense/slam/loops/trajectory_correction.hpp"

namespace featsense::mapping {

slam::loops::MapKeyframe map_keyframe(const storage::StoredKeyframe& stored) {
  slam::loops::MapKeyframe out;
  out.session = stored.session;
  out.index = stored.index;
  const slam::Trajectory pose = from_store_poses({stored.pose});
  out.stamp_ns = pose.stamps_ns.front();
  out.T_map_sensor = pose.poses.front();
  if (stored.descriptor_rows > 0 && stored.descriptor_cols > 0) {
    out.descriptor = slam::loops::scan_context_from_bins(stored.descriptor_rows,
                                                         stored.descriptor_cols, stored.descriptor);
  }
  out.cloud = slam::loops::CompactCloud::from_coordinates(stored.cloud_cm);
  return out;
}

slam::loops::KeyframeRecord keyframe_record(const slam::loops::MapKeyframe& keyframe,
                                            const Eigen::Isometry3d& T_map_sensor) {
  return {keyframe.stamp_ns, keyframe.travelled_m, T_map_sensor, keyframe.descriptor,
          keyframe.cloud};
}

std::vector<double> travelled_along(const slam::Trajectory& path) {
  std::vector<double> out(path.size(), 0.0);
  for (size_t i = 1; i < path.size(); ++i)
    out[i] = out[i - 1] + (path.poses[i].translation() - path.poses[i - 1].translation()).norm();
  return out;
}

namespace {

/// The index of the pose of `path` nearest `stamp_ns` (stamps increasing).
size_t nearest_pose(const slam::Trajectory& path, int64_t stamp_ns) {
  const auto it = std::lower_bound(path.stamps_ns.begin(), path.stamps_ns.end(), stamp_ns);
  size_t i = static_cast<size_t>(it - path.stamps_ns.begin());
  if (i == path.size()) return path.size() - 1;
  if (i > 0 && stamp_ns - path.stamps_ns[i - 1] < path.stamps_ns[i] - stamp_ns) --i;
  return i;
}

}  // namespace

void travelled_along_path(std::vector<slam::loops::MapKeyframe>& keyframes, size_t first,
                          size_t end, const slam::Trajectory& path) {
  if (path.size() == 0) return;
  const std::vector<double> travelled = travelled_along(path);
  for (size_t k = first; k < end; ++k)
    keyframes[k].travelled_m = travelled[nearest_pose(path, keyframes[k].stamp_ns)];
}

slam::Trajectory moved_by(const Eigen::Isometry3d& T, const slam::Trajectory& path) {
  slam::Trajectory out;
  for (size_t i = 0; i < path.size(); ++i) out.push_back(path.stamps_ns[i], T * path.poses[i]);
  return out;
}

slam::Trajectory moved_path(const slam::Trajectory& path,
                            const std::vector<slam::loops::MapKeyframe>& keyframes, size_t first,
                            size_t end, const std::vector<Eigen::Isometry3d>& after) {
  slam::loops::TrajectoryCorrection correction;
  double last_m = -1.0;
  for (size_t k = first; k < end; ++k) {
    // Travelled distances must increase; a keyframe at the same place as the last adds
    // nothing.
    if (keyframes[k].travelled_m <= last_m) continue;
    correction.add_keyframe(keyframes[k].travelled_m, keyframes[k].T_map_sensor, after[k]);
    last_m = keyframes[k].travelled_m;
  }
  const std::vector<double> travelled = travelled_along(path);
  slam::Trajectory out;
  for (size_t i = 0; i < path.size(); ++i)
    out.push_back(path.stamps_ns[i], correction.apply(travelled[i], path.poses[i]));
  return out;
}

SavedMap read_saved_map(const std::filesystem::path& path) {
  SavedMap out;
  out.path = path;
  const storage::Hdf5ChunkStore store(path);
  out.metadata = store.metadata();
  const slam::Trajectory all = from_store_poses(store.read_trajectory());
  out.scans = all.size();
  const std::vector<storage::MapSession> sessions = store.read_sessions();
  uint64_t counted = 0;
  for (const storage::MapSession& session : sessions) counted += session.scans;
  // The stored trajectory is every session's poses, one after the other.
  const bool splits = !sessions.empty() && counted == all.size();
  size_t next = 0;
  for (const storage::MapSession& session : sessions) {
    SavedSession saved{session, {}};
    if (splits) {
      for (uint64_t i = 0; i < session.scans; ++i, ++next)
        saved.poses.push_back(all.stamps_ns[next], all.poses[next]);
    }
    out.sessions.push_back(std::move(saved));
  }
  for (const storage::StoredKeyframe& stored : store.read_keyframes()) {
    try {
      out.keyframes.push_back(map_keyframe(stored));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(path.string() + ": keyframe " + std::to_string(stored.index) +
                               " of session " + std::to_string(stored.session) + ": " + e.what());
    }
  }
  slam::loops::travelled_from_positions(out.keyframes);
  for (size_t first = 0; first < out.keyframes.size();) {
    size_t end = first;
    while (end < out.keyframes.size() && out.keyframes[end].session == out.keyframes[first].session)
      ++end;
    for (const SavedSession& saved : out.sessions) {
      if (saved.session.id == out.keyframes[first].session)
        travelled_along_path(out.keyframes, first, end, saved.poses);
    }
    first = end;
  }
  return out;
}

}  // namespace featsense::mapping
