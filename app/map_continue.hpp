#pragma once
// `featsense map INPUT --continue MAP.h5` without poses: the recording's odometry runs in a
// frame of its own (its first scan) while its keyframes are matched against the map's
// (relocalizer.hpp); nothing is written until it is placed. Placed, its keyframes join the
// map's in one pose graph with links between the sessions (session_links.hpp). Where the
// links move the map's earlier keyframes by more than a quarter voxel and every earlier
// input can be read again, the whole map is made again from the inputs with the corrected
// poses (into a new file that replaces the old one once complete); otherwise the earlier map
// stays as it is and the recording is mapped into it with its corrected poses.

#include <nlohmann/json.hpp>

#include <Eigen/Geometry>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "featsense/config/config.hpp"
#include "featsense/slam/scan_locator.hpp"
#include "featsense/slam/scan_source.hpp"
#include "map_job.hpp"
#include "map_pass.hpp"
#include "map_pipeline.hpp"
#include "map_sessions.hpp"
#include "saved_map.hpp"

namespace featsense::app {

/// The recording could not be placed in the map: nothing was written into it.
class RelocalizationFailed : public std::runtime_error {
 public:
  RelocalizationFailed(const std::string& why, nlohmann::json report)
      : std::runtime_error(why), report_(std::move(report)) {}
  /// What was tried, for report.json.
  const nlohmann::json& report() const { return report_; }

 private:
  nlohmann::json report_;
};

struct ContinueRequest {
  std::filesystem::path old_map;  ///< --continue
  std::filesystem::path out;      ///< OUT: OUT/map.h5 is written
  std::string sensor_name;
  bool overwrite = false;
  SessionDescription session;
  /// --initial-pose: where the recording's first scan lies in the map, roughly.
  std::optional<Eigen::Isometry3d> guess;
};

struct ContinuedRun {
  MapPassOutput pass;            ///< the pass that mapped this recording (its poses: map frame)
  PipelineResult first;          ///< the odometry's pass, in the recording's own frame
  slam::Trajectory final_poses;  ///< this recording's poses in the map frame
  nlohmann::json report;         ///< report.json's "relocalization"
  std::string second_pass;       ///< what the mapping pass did, for the report
};

/// `odometry` must start at the identity (the recording's own frame). `pipeline` as for a map
/// run (refinement, loops); `config` takes the saved map's voxel size and tau. Throws
/// RelocalizationFailed (report.json written, the map untouched), Interrupted, ConfigError or
/// std::runtime_error.
ContinuedRun map_into_saved_map(slam::ScanSource& source, slam::ScanLocator& odometry,
                                PipelineSettings pipeline, config::Config& config,
                                const ContinueRequest& request, const SourceReopener& reopen);

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
/// in order, into `into` (replaced). Throws Interrupted, InputError or std::runtime_error.
void remap_sessions(const std::vector<SessionRemap>& sessions, const std::filesystem::path& into,
                    const PipelineSettings& replay, config::Config& config,
                    const std::string& sensor_name);

/// --initial-pose "x,y,z,yaw_deg" as a pose (map <- the recording's first scan). Throws
/// ConfigError.
Eigen::Isometry3d parse_initial_pose(const std::string& text);

}  // namespace featsense::app
