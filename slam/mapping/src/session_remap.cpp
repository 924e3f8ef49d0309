#include "featsense/mapping/session_remap.hpp"

#include <memory>

#include "featsense/mapping/map_pipeline.hpp"
#include "featsense/mapping/recording.hpp"
#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/storage/chunk_store.hpp"

namespace featsense::mapping {
namespace {

namespace fs = std::filesystem;
using slam::loops::MapKeyframe;

}  // namespace

std::string why_sessions_cannot_be_read(const SavedMap& saved, const config::Config& config) {
  for (const SavedSession& s : saved.sessions) {
    const std::string name = "session " + std::to_string(s.session.id);
    if (s.poses.size() == 0) return name + " has no poses of its own in the map file";
    if (s.session.input.empty() || !fs::exists(s.session.input))
      return name + "'s input " + (s.session.input.empty() ? "(none named)" : s.session.input) +
             " is gone";
    try {
      open_recording(s.session.input, config);
    } catch (const std::exception& e) {
      return name + "'s input " + s.session.input + " cannot be read: " + e.what();
    }
  }
  return "";
}

std::vector<slam::loops::KeyframeRecord> records_of(const std::vector<MapKeyframe>& keyframes,
                                                    size_t first, size_t end,
                                                    const std::vector<Eigen::Isometry3d>& poses) {
  std::vector<slam::loops::KeyframeRecord> out;
  for (size_t k = first; k < end; ++k) out.push_back(keyframe_record(keyframes[k], poses[k]));
  return out;
}

std::vector<SessionRemap> session_remaps(const SavedMap& saved,
                                         const std::vector<MapKeyframe>& keyframes, size_t first,
                                         uint32_t id_offset, const Eigen::Isometry3d& T_into_saved,
                                         const std::vector<Eigen::Isometry3d>& poses,
                                         const std::string& note) {
  std::vector<SessionRemap> out;
  for (const SavedSession& session : saved.sessions) {
    size_t end = first;
    while (end < keyframes.size() && keyframes[end].session == session.session.id + id_offset)
      ++end;
    out.push_back(
        {{session.session.input, session.session.format, session.session.placement + note},
         moved_path(moved_by(T_into_saved, session.poses), keyframes, first, end, poses),
         records_of(keyframes, first, end, poses)});
    first = end;
  }
  return out;
}

size_t remap_sessions(const std::vector<SessionRemap>& sessions, const fs::path& into,
                      const PassSettings& replay, const config::Config& config,
                      const std::string& sensor_name, const RunEvents& events,
                      const std::vector<ScanReintegration>* only) {
  size_t integrated = 0;
  for (size_t s = 0; s < sessions.size(); ++s) {
    const SessionRemap& session = sessions[s];
    PassSettings settings = replay;
    if (only) settings.reintegrate = &only->at(s);
    if (only) {
      events.info("integrating " + std::to_string(settings.reintegrate->origins.size()) + " of " +
                  std::to_string(session.poses.size()) + " scans of " + session.description.input +
                  " again");
    } else {
      events.info("mapping " + session.description.input + " again with its corrected poses");
    }
    const std::unique_ptr<slam::ScanSource> source =
        open_recording(session.description.input, config);
    const std::unique_ptr<slam::ScanLocator> locator =
        slam::make_given_pose_locator(session.poses, config.odometry.deskew);
    PipelineSettings pipeline;
    if (session.poses.size() > 0) {
      // The poses' stamps come from the map (storage::TrajectoryPose): the first and the last
      // scan may lie a few hundred nanoseconds outside them.
      pipeline.range.first_stamp_ns =
          session.poses.stamps_ns.front() - storage::kStoredStampToleranceNs;
      pipeline.range.last_stamp_ns =
          session.poses.stamps_ns.back() + storage::kStoredStampToleranceNs;
    }
    const PassResult pass = run_pass(
        *source, *locator, settings, config,
        {into, sensor_name, s == 0 ? std::nullopt : std::optional<std::string>(into.string()), true,
         session.description, &session.keyframes},
        events, pipeline);
    if (pass.interrupted) throw Interrupted("interrupted");
    integrated += pass.frames_mapped;
  }
  return integrated;
}

std::vector<KeyframeId> keyframe_ids(const std::vector<MapKeyframe>& keyframes) {
  std::vector<KeyframeId> out;
  out.reserve(keyframes.size());
  for (const MapKeyframe& k : keyframes) out.push_back({k.session, k.index, k.stamp_ns});
  return out;
}

}  // namespace featsense::mapping
