#pragma once
// The sessions of a saved map mapped again: a TSDF cannot be moved without resampling it, but
// its sessions' inputs can be read again. Used where links to a new session moved the map's
// keyframes (a recording continuing the map) and where two maps are merged.

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/mapping/map_pass.hpp"
#include "featsense/mapping/map_sessions.hpp"
#include "featsense/mapping/reintegration_plan.hpp"
#include "featsense/mapping/run_events.hpp"
#include "featsense/mapping/saved_map.hpp"
#include "featsense/slam/loops/map_keyframe.hpp"
#include "featsense/slam/loops/session_links.hpp"

namespace featsense::mapping {

/// Why the sessions of `saved` cannot be mapped again from their inputs (empty: they can).
std::string why_sessions_cannot_be_read(const SavedMap& saved, const config::Config& config);

/// Keyframes [first, end) as a map file records them, at `poses` (same indexing).
std::vector<slam::loops::KeyframeRecord> records_of(
    const std::vector<slam::loops::MapKeyframe>& keyframes, size_t first, size_t end,
    const std::vector<Eigen::Isometry3d>& poses);

/// A session to be mapped again: its input and how it was placed, its final poses and
/// keyframes.
struct SessionRemap {
  SessionDescription description;
  slam::Trajectory poses;
  std::vector<slam::loops::KeyframeRecord> keyframes;
};

/// The sessions of `saved` to be mapped again: each one's poses taken into the new map's frame
/// by `T_into_saved`, then moved as its keyframes moved (its keyframes are the run of
/// `keyframes` from `first` whose session is its id + `id_offset`; `poses` their poses after),
/// its placement text followed by `note`.
std::vector<SessionRemap> session_remaps(const SavedMap& saved,
                                         const std::vector<slam::loops::MapKeyframe>& keyframes,
                                         size_t first, uint32_t id_offset,
                                         const Eigen::Isometry3d& T_into_saved,
                                         const std::vector<Eigen::Isometry3d>& poses,
                                         const std::string& note);

/// Maps each session again from its input with its poses (interpolated within each sweep),
/// in order, into `into` (replaced). Throws Interrupted, slam::InputError or
/// std::runtime_error.
/// With `only`, session s integrates only the scans of (*only)[s], each with the local map
/// the plan gives it (reintegration_plan.hpp). Returns the scans integrated.
size_t remap_sessions(const std::vector<SessionRemap>& sessions, const std::filesystem::path& into,
                      const PassSettings& replay, const config::Config& config,
                      const std::string& sensor_name, const RunEvents& events,
                      const std::vector<ScanReintegration>* only = nullptr);

/// What remap_sessions_where_moved did.
struct ReintegrationCounts {
  /// Every scan was integrated again (the map before could not be used); `why` says why.
  bool whole = false;
  std::string why;
  size_t scans = 0;
  size_t scans_moved = 0;
  size_t scans_reintegrated = 0;  ///< as integrated; a warning where not all the plan named
  size_t chunks_before = 0;       ///< chunks of the map before
  size_t chunks_changed = 0;      ///< chunks a moved scan reached, made again
  size_t chunks_kept = 0;         ///< chunks of the map before copied byte for byte
  double plan_s = 0.0;
  double reintegrate_s = 0.0;
  double assemble_s = 0.0;
};

/// remap_sessions, integrating again only what moved (the rule: reintegration_plan.hpp): the
/// first sessions of `sessions` are those of `before` (the map file they were integrated into,
/// in the same frame), in order; any after them are new to it. `into` gets the changed chunks
/// as a full re-map makes them and every other chunk of `before` byte for byte; its sessions,
/// poses and keyframes are a full re-map's. Throws as remap_sessions.
ReintegrationCounts remap_sessions_where_moved(
    const SavedMap& before, const std::vector<SessionRemap>& sessions,
    const std::filesystem::path& into, const PassSettings& replay, const config::Config& config,
    const std::string& sensor_name, const RunEvents& events);

/// A keyframe by session and index, for reports of links between sessions.
struct KeyframeId {
  uint32_t session = 0;
  uint32_t index = 0;
  int64_t stamp_ns = 0;
};
std::vector<KeyframeId> keyframe_ids(const std::vector<slam::loops::MapKeyframe>& keyframes);

/// The links between sessions of a joined graph, with the keyframes they join (by the
/// indices in the links).
struct SessionLinks {
  slam::loops::SessionLinkResult linked;
  std::vector<KeyframeId> keyframes;
};

}  // namespace featsense::mapping
