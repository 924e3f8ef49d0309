#include "mapper_continuation.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <utility>
#include <vector>

#include "featsense/config/config_error.hpp"
#include "featsense/mapping/map_store.hpp"
#include "featsense/mapping/session_remap.hpp"
#include "featsense/slam/loops/session_links.hpp"
#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/slam/trajectory/scan_motions.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"

namespace featsense::mapping {
namespace {

namespace fs = std::filesystem;
using slam::loops::MapKeyframe;

std::string rejections_text(const std::map<std::string, size_t>& rejected) {
  std::string out;
  for (const auto& [reason, count] : rejected)
    out += (out.empty() ? "" : ", ") + std::to_string(count) + " " + reason;
  return out.empty() ? "none" : out;
}

/// The keyframes of the recording in the map frame: its loop closer's keyframes moved by the
/// placement, which was found for the front end's pose of one keyframe.
std::vector<MapKeyframe> placed_keyframes(const LoopOutcome& loops,
                                          const slam::loops::Relocalization& placement,
                                          uint32_t session, Eigen::Isometry3d& T_map_graph) {
  T_map_graph = placement.T_map_session;
  for (size_t i = 0; i < loops.before.size(); ++i) {
    if (loops.before.stamps_ns[i] != placement.stamp_ns) continue;
    for (const slam::loops::KeyframeRecord& record : loops.keyframes) {
      if (record.stamp_ns == placement.stamp_ns)
        T_map_graph =
            placement.T_map_session * loops.before.poses[i] * record.T_map_sensor.inverse();
    }
  }
  std::vector<MapKeyframe> out;
  for (size_t k = 0; k < loops.keyframes.size(); ++k) {
    const slam::loops::KeyframeRecord& record = loops.keyframes[k];
    MapKeyframe keyframe;
    keyframe.session = session;
    keyframe.index = static_cast<uint32_t>(k);
    keyframe.stamp_ns = record.stamp_ns;
    keyframe.T_map_sensor = T_map_graph * record.T_map_sensor;
    keyframe.travelled_m = record.travelled_m;
    keyframe.descriptor = record.descriptor;
    keyframe.cloud = record.cloud;
    out.push_back(std::move(keyframe));
  }
  return out;
}

std::string not_placed_why(const RelocalizationReport& report, const LoopOutcome& loops,
                           const std::string& input) {
  const slam::loops::RelocalizationCounts& c = report.tried;
  std::ostringstream why;
  why << input << " could not be placed in " << report.map << ": none of the " << c.keyframes
      << " keyframes of its "
      << (loops.relocalize_gave_up ? "first " + std::to_string(report.max_scans)
                                   : std::to_string(loops.before.size()))
      << " scans"
      << " matched the map's " << report.map_keyframes << " keyframes (" << c.candidates
      << " candidates, " << c.verified << " verified; rejected: " << rejections_text(c.rejected)
      << "). The recording may show another place, or start where the map has not been "
         "(--initial-pose x,y,z,yaw_deg helps where that is known). "
      << report.map << " is unchanged.";
  return why.str();
}

/// The largest move of keyframes [0, end) from their poses in `keyframes` to `after`.
void largest_move(const std::vector<MapKeyframe>& keyframes, size_t end,
                  const std::vector<Eigen::Isometry3d>& after, double& moved_m, double& moved_deg) {
  moved_m = 0.0;
  moved_deg = 0.0;
  for (size_t k = 0; k < end; ++k) {
    moved_m = std::max(moved_m,
                       (after[k].translation() - keyframes[k].T_map_sensor.translation()).norm());
    moved_deg = std::max(
        moved_deg, slam::rotation_angle_deg(after[k].rotation() *
                                            keyframes[k].T_map_sensor.rotation().transpose()));
  }
}

}  // namespace

Mapper::Continuation::Continuation(const MapperSettings& settings, const RunEvents& events) {
  const fs::path old_map(*settings.continue_from);
  const fs::path& map_out = settings.map_path;
  if (old_map.extension() == ".vdb") {
    throw config::ConfigError("--continue " + old_map.string() +
                              ": a .vdb keeps no keyframes to place a recording by; give the "
                              "recording's poses in its frame with --gt");
  }
  if (!fs::exists(old_map))
    throw std::runtime_error("--continue: no such map: " + old_map.string());
  const bool in_place = fs::exists(map_out) && fs::equivalent(old_map, map_out);
  if (fs::exists(map_out) && !in_place && !settings.overwrite)
    throw std::runtime_error(map_out.string() + " exists; pass --overwrite to replace it");
  if (!settings.reopen) {
    throw std::runtime_error(
        "placing a recording in a saved map reads it twice (the odometry, "
        "then the map): this input cannot be read twice");
  }
  saved_ = read_saved_map(old_map);
  if (saved_.keyframes.empty()) {
    throw std::runtime_error(
        old_map.string() +
        " keeps no keyframes (it was made with given poses, with loop closure off or by an "
        "older featsense): a recording is placed in a map by its keyframes; continue it with "
        "--gt poses in its frame instead");
  }
  settings_ = slam::loops::relocalize_from_config(settings.config);
  settings_.guess = settings.initial_guess;
  relocalizer_ = std::make_unique<slam::loops::Relocalizer>(saved_.keyframes, settings_);
  max_scans_ = static_cast<size_t>(settings.config.relocalize.max_scans);
  events.info("placing " + settings.session.input + " in " + old_map.string() + " by its " +
              std::to_string(saved_.keyframes.size()) + " keyframes (" +
              std::to_string(saved_.sessions.size()) + " sessions)" +
              (settings.initial_guess ? ", from the given initial pose" : ""));
}

void Mapper::Continuation::finish(Mapper& mapper, MapResult& result) {
  const Placed placed = place(mapper, result);
  if (!mapper.settings_.integrate) {
    // Poses only: placed, and nothing written into any map.
    result.second = result.first;
    result.second->poses = result.final_poses;
    result.second_pass = {SecondPass::kPosesOnly, "--poses-only: placed, no map"};
    return;
  }
  map_placed(mapper, result, placed);
}

Mapper::Continuation::Placed Mapper::Continuation::place(const Mapper& mapper, MapResult& result) {
  const MapperSettings& request = mapper.settings_;
  const std::string old_map = *request.continue_from;
  const std::string& input = request.session.input;
  const LoopOutcome& loops = *result.first.loops;
  RelocalizationReport& report = result.relocalization.emplace();
  report.map = old_map;
  report.map_sessions = saved_.sessions.size();
  report.map_keyframes = saved_.keyframes.size();
  report.max_scans = max_scans_;
  report.tried = loops.relocalize_counts;
  if (!loops.relocalization) {
    if (result.first.interrupted) {
      throw Interrupted("interrupted before " + input + " was placed in " + old_map +
                        ", which is unchanged");
    }
    report.why = not_placed_why(report, loops, input);
    throw RelocalizationFailed(report.why, report);
  }
  if (result.first.interrupted) {
    throw Interrupted("interrupted after " + input + " was placed in " + old_map +
                      ", before it was mapped: the map is unchanged");
  }
  const slam::loops::Relocalization& placement = *loops.relocalization;
  report.placement = placement;
  Placed placed;
  for (const SavedSession& s : saved_.sessions)
    placed.session_id = std::max(placed.session_id, s.session.id + 1);
  Eigen::Isometry3d T_map_graph;
  placed.keyframes = saved_.keyframes;
  placed.first_new = placed.keyframes.size();
  for (MapKeyframe& k : placed_keyframes(loops, placement, placed.session_id, T_map_graph))
    placed.keyframes.push_back(std::move(k));
  const slam::Trajectory placed_path = moved_by(T_map_graph, loops.corrected);
  travelled_along_path(placed.keyframes, placed.first_new, placed.keyframes.size(), placed_path);
  const MapKeyframe& matched = saved_.keyframes[placement.map_keyframe];
  report.session = placed.session_id;
  report.seconds_in =
      static_cast<double>(placement.stamp_ns - loops.before.stamps_ns.front()) * 1e-9;
  report.matched = {matched.session, matched.index, matched.stamp_ns};
  char text[200];
  std::snprintf(text, sizeof text,
                "placed at keyframe %zu (scan %.1f s in): it matched session %u keyframe %u "
                "(fitness %.1f mm, %zu keyframes agreeing)",
                placement.keyframe, report.seconds_in, matched.session, matched.index,
                1000.0 * placement.fitness_m, placement.agreeing);
  mapper.events_.info(text);

  slam::loops::SessionLinkSettings link_settings;
  link_settings.loop = settings_.loop;
  report.links.linked =
      slam::loops::link_sessions(placed.keyframes, link_settings, placed.session_id);
  report.links.keyframes = keyframe_ids(placed.keyframes);
  const slam::loops::SessionLinkResult& linked = report.links.linked;
  largest_move(placed.keyframes, placed.first_new, linked.poses, report.earlier_moved_max_m,
               report.earlier_moved_max_deg);
  result.final_poses = moved_path(placed_path, placed.keyframes, placed.first_new,
                                  placed.keyframes.size(), linked.poses);
  const bool moved = moves_the_map(report.earlier_moved_max_m, saved_.metadata.voxel_size_m);
  report.earlier =
      plan_earlier_sessions(report.earlier_moved_max_m, saved_.metadata.voxel_size_m,
                            moved ? why_sessions_cannot_be_read(saved_, request.config) : "");
  if (report.earlier.kind == EarlierSessions::kKept) {
    std::snprintf(text, sizeof text, "the links moved the map's keyframes by up to %.1f mm, but ",
                  1000.0 * report.earlier_moved_max_m);
    mapper.events_.warn(text + report.earlier.reason);
  }
  std::snprintf(text, sizeof text,
                "relocalized: keyframe %zu matched session %u keyframe %u (fitness %.1f mm, %zu "
                "keyframes agreeing); %zu links to earlier sessions",
                placement.keyframe, matched.session, matched.index, 1000.0 * placement.fitness_m,
                placement.agreeing, linked.links.size());
  placed.session = request.session;
  placed.session.placement = text;
  return placed;
}

void Mapper::Continuation::map_placed(Mapper& mapper, MapResult& result, const Placed& placed) {
  const MapperSettings& request = mapper.settings_;
  const config::Config& config = mapper.settings_.config;
  const RunEvents& events = mapper.events_;
  const std::string old_map = *request.continue_from;
  const RelocalizationReport& report = *result.relocalization;
  const std::vector<Eigen::Isometry3d>& linked_poses = report.links.linked.poses;
  // The mapping pass(es): this recording with its final poses, deskewed as the odometry
  // placed each scan; before it, where they moved, every earlier session again.
  PassSettings replay = mapper.pass_settings_;
  replay.refine.reset();
  replay.loops.reset();
  replay.relocalize.reset();
  replay.integrate = true;
  const std::vector<slam::loops::KeyframeRecord> records =
      records_of(placed.keyframes, placed.first_new, placed.keyframes.size(), linked_poses);
  const auto this_recording = [&](const fs::path& into, const std::optional<std::string>& from,
                                  bool overwrite) {
    const std::unique_ptr<slam::ScanSource> source_again = request.reopen();
    const std::unique_ptr<slam::ScanLocator> locator =
        config.odometry.deskew
            ? slam::make_replay_locator(result.final_poses, result.first.scan_motions)
            : slam::make_given_pose_locator(result.final_poses, false);
    PipelineSettings pipeline;
    pipeline.range = request.range;
    return run_pass(*source_again, *locator, replay, config,
                    {into, request.sensor.name, from, overwrite, placed.session, &records}, events,
                    pipeline);
  };
  if (report.earlier.kind != EarlierSessions::kMappedAgain) {
    events.info("mapping " + request.session.input + " into " + old_map +
                " with its poses in the map");
    result.second = this_recording(request.map_path, old_map, request.overwrite);
    result.second_pass = {SecondPass::kIntoSavedMap,
                          "mapped into the saved map with the placed, corrected poses"};
    return;
  }
  const fs::path rebuilt =
      fs::path(request.map_path)
          .replace_extension(".rebuilt" + request.map_path.extension().string());
  try {
    build_then_replace(rebuilt, request.map_path, [&] {
      result.relocalization->reintegration = remap_sessions_where_moved(
          saved_,
          session_remaps(saved_, placed.keyframes, 0, 0, Eigen::Isometry3d::Identity(),
                         linked_poses,
                         "; moved by the links of session " + std::to_string(placed.session_id)),
          rebuilt, replay, config, request.sensor.name, events);
      result.second = this_recording(rebuilt, rebuilt.string(), true);
      if (result.second->interrupted) throw Interrupted("interrupted");
    });
  } catch (const Interrupted&) {
    throw Interrupted("interrupted while the map was made again; " + old_map + " is unchanged");
  }
  result.second_pass = {SecondPass::kSessionsMappedAgain,
                        "every session mapped again with the corrected poses"};
}

}  // namespace featsense::mapping
