#include "map_continue.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <utility>
#include <vector>

#include "featsense/config/config_error.hpp"
#include "featsense/slam/loops/relocalizer.hpp"
#include "featsense/slam/loops/session_links.hpp"
#include "featsense/slam/trajectory/given_pose_locator.hpp"
#include "featsense/slam/trajectory/scan_motions.hpp"
#include "featsense/slam/trajectory/trajectory_metrics.hpp"
#include "json_output.hpp"
#include "map_store.hpp"
#include "saved_map.hpp"
#include "session_links_report.hpp"
#include "source_options.hpp"
#include "stop_signal.hpp"
#include "timing_stats.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;
using slam::loops::MapKeyframe;

constexpr double kPi = 3.14159265358979323846;

nlohmann::json pose_json(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d t = T.translation();
  const Eigen::Vector3d x = T.rotation().col(0);
  return {{"x", t.x()},
          {"y", t.y()},
          {"z", t.z()},
          {"yaw_deg", std::atan2(x.y(), x.x()) * 180.0 / kPi},
          {"tilt_deg", std::acos(std::clamp(T.rotation()(2, 2), -1.0, 1.0)) * 180.0 / kPi}};
}

std::string rejections_text(const std::map<std::string, size_t>& rejected) {
  std::string out;
  for (const auto& [reason, count] : rejected)
    out += (out.empty() ? "" : ", ") + std::to_string(count) + " " + reason;
  return out.empty() ? "none" : out;
}

nlohmann::json tried_json(const slam::loops::RelocalizationCounts& counts) {
  return {{"keyframes", counts.keyframes},
          {"candidates", counts.candidates},
          {"verified", counts.verified},
          {"rejected", counts.rejected},
          {"keyframe_ms", timing_json(counts.keyframe_ms)}};
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

slam::Trajectory moved_by(const Eigen::Isometry3d& T, const slam::Trajectory& path) {
  slam::Trajectory out;
  for (size_t i = 0; i < path.size(); ++i) out.push_back(path.stamps_ns[i], T * path.poses[i]);
  return out;
}

}  // namespace

std::string why_sessions_cannot_be_read(const SavedMap& saved, const config::Config& config) {
  for (const SavedSession& s : saved.sessions) {
    const std::string name = "session " + std::to_string(s.session.id);
    if (s.poses.size() == 0) return name + " has no poses of its own in the map file";
    if (s.session.input.empty() || !fs::exists(s.session.input))
      return name + "'s input " + (s.session.input.empty() ? "(none named)" : s.session.input) +
             " is gone";
    try {
      InputOptions input;
      input.input = s.session.input;
      input.open(config);
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

void remap_sessions(const std::vector<SessionRemap>& sessions, const fs::path& into,
                    const PipelineSettings& replay, config::Config& config,
                    const std::string& sensor_name) {
  for (size_t s = 0; s < sessions.size(); ++s) {
    const SessionRemap& session = sessions[s];
    spdlog::info("mapping {} again with its corrected poses", session.description.input);
    InputOptions input;
    input.input = session.description.input;
    const std::unique_ptr<slam::ScanSource> source = input.open(config);
    const std::unique_ptr<slam::ScanLocator> locator =
        slam::make_given_pose_locator(session.poses, config.odometry.deskew);
    PipelineSettings pipeline = replay;
    pipeline.range = {};
    if (session.poses.size() > 0) {
      pipeline.range.first_stamp_ns = session.poses.stamps_ns.front();
      pipeline.range.last_stamp_ns = session.poses.stamps_ns.back();
    }
    pipeline.total_frames = source->info().frames;
    const MapPassOutput pass = run_map_pass(
        *source, *locator, pipeline, config,
        {into, sensor_name, s == 0 ? std::nullopt : std::optional<std::string>(into.string()), true,
         session.description, &session.keyframes});
    if (pass.result.interrupted) throw Interrupted("interrupted");
  }
}

Eigen::Isometry3d parse_initial_pose(const std::string& text) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size() || !std::isfinite(values.back())) values.clear();
    } catch (const std::exception&) {
      values.clear();
      break;
    }
    if (values.empty()) break;
  }
  if (values.size() != 4) {
    throw config::ConfigError("--initial-pose: expected x,y,z,yaw_deg (metres, degrees), got '" +
                              text + "'");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(values[0], values[1], values[2]);
  T.linear() =
      Eigen::AngleAxisd(values[3] * kPi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

ContinuedRun map_into_saved_map(slam::ScanSource& source, slam::ScanLocator& odometry,
                                PipelineSettings pipeline, config::Config& config,
                                const ContinueRequest& request, const SourceReopener& reopen) {
  const fs::path map_out = request.out / "map.h5";
  if (request.old_map.extension() == ".vdb") {
    throw config::ConfigError("--continue " + request.old_map.string() +
                              ": a .vdb keeps no keyframes to place a recording by; give the "
                              "recording's poses in its frame with --gt");
  }
  if (!fs::exists(request.old_map))
    throw std::runtime_error("--continue: no such map: " + request.old_map.string());
  const bool in_place = fs::exists(map_out) && fs::equivalent(request.old_map, map_out);
  if (fs::exists(map_out) && !in_place && !request.overwrite)
    throw std::runtime_error(map_out.string() + " exists; pass --overwrite to replace it");
  if (!reopen) {
    throw std::runtime_error(
        "placing a recording in a saved map reads it twice (the odometry, "
        "then the map): this input cannot be read twice");
  }
  const SavedMap saved = read_saved_map(request.old_map);
  adopt_map_geometry(saved.metadata, request.old_map.string(), config);
  if (saved.keyframes.empty()) {
    throw std::runtime_error(
        request.old_map.string() +
        " keeps no keyframes (it was made with given poses, with loop closure off or by an "
        "older featsense): a recording is placed in a map by its keyframes; continue it with "
        "--gt poses in its frame instead");
  }

  slam::loops::RelocalizeSettings settings;
  settings.loop = slam::loops::from_config(config);
  settings.confirmations = static_cast<size_t>(config.relocalize.confirmations);
  settings.guess = request.guess;
  slam::loops::Relocalizer relocalizer(saved.keyframes, settings);
  const size_t max_scans = static_cast<size_t>(config.relocalize.max_scans);
  spdlog::info("placing {} in {} by its {} keyframes ({} sessions){}", request.session.input,
               request.old_map.string(), saved.keyframes.size(), saved.sessions.size(),
               request.guess ? ", from the given initial pose" : "");

  ContinuedRun run;
  PipelineSettings first_pass = pipeline;
  first_pass.integrate = false;
  if (!first_pass.loops) first_pass.loops = settings.loop;
  first_pass.relocalize = RelocalizeStage{&relocalizer, max_scans};
  run.first = run_map_pipeline(source, odometry, MapOpener(), first_pass);
  const LoopOutcome& loops = *run.first.loops;
  nlohmann::json& report = run.report;
  report["map"] = request.old_map.string();
  report["map_sessions"] = saved.sessions.size();
  report["map_keyframes"] = saved.keyframes.size();
  report["max_scans"] = max_scans;
  report["tried"] = tried_json(loops.relocalize_counts);
  if (!loops.relocalization) {
    report["placed"] = false;
    if (run.first.interrupted) {
      throw Interrupted("interrupted before " + request.session.input + " was placed in " +
                        request.old_map.string() + ", which is unchanged");
    }
    const slam::loops::RelocalizationCounts& c = loops.relocalize_counts;
    std::ostringstream why;
    why << request.session.input << " could not be placed in " << request.old_map.string()
        << ": none of the " << c.keyframes << " keyframes of its "
        << (loops.relocalize_gave_up ? "first " + std::to_string(max_scans)
                                     : std::to_string(loops.before.size()))
        << " scans"
        << " matched the map's " << saved.keyframes.size() << " keyframes (" << c.candidates
        << " candidates, " << c.verified << " verified; rejected: " << rejections_text(c.rejected)
        << "). The recording may show another place, or start where the map has not been "
           "(--initial-pose x,y,z,yaw_deg helps where that is known). "
        << request.old_map.string() << " is unchanged.";
    report["why"] = why.str();
    throw RelocalizationFailed(why.str(), report);
  }
  if (run.first.interrupted) {
    throw Interrupted("interrupted after " + request.session.input + " was placed in " +
                      request.old_map.string() + ", before it was mapped: the map is unchanged");
  }
  const slam::loops::Relocalization& placement = *loops.relocalization;
  uint32_t session_id = 0;
  for (const SavedSession& s : saved.sessions) session_id = std::max(session_id, s.session.id + 1);
  Eigen::Isometry3d T_map_graph;
  std::vector<MapKeyframe> keyframes = saved.keyframes;
  const size_t first_new = keyframes.size();
  for (MapKeyframe& k : placed_keyframes(loops, placement, session_id, T_map_graph))
    keyframes.push_back(std::move(k));
  const slam::Trajectory placed_path = moved_by(T_map_graph, loops.corrected);
  travelled_along_path(keyframes, first_new, keyframes.size(), placed_path);
  const MapKeyframe& matched = saved.keyframes[placement.map_keyframe];
  spdlog::info(
      "placed at keyframe {} (scan {:.1f} s in): it matched session {} keyframe {} "
      "(fitness {:.1f} mm, {} keyframes agreeing)",
      placement.keyframe,
      static_cast<double>(placement.stamp_ns - loops.before.stamps_ns.front()) * 1e-9,
      matched.session, matched.index, 1000.0 * placement.fitness_m, placement.agreeing);

  slam::loops::SessionLinkSettings link_settings;
  link_settings.loop = settings.loop;
  const slam::loops::SessionLinkResult linked =
      slam::loops::link_sessions(keyframes, link_settings, session_id);
  double moved_m = 0.0;
  double moved_deg = 0.0;
  for (size_t k = 0; k < first_new; ++k) {
    moved_m = std::max(
        moved_m, (linked.poses[k].translation() - keyframes[k].T_map_sensor.translation()).norm());
    moved_deg = std::max(
        moved_deg, slam::rotation_angle_deg(linked.poses[k].rotation() *
                                            keyframes[k].T_map_sensor.rotation().transpose()));
  }
  run.final_poses = moved_path(placed_path, keyframes, first_new, keyframes.size(), linked.poses);
  const double quarter_voxel_m = 0.25 * saved.metadata.voxel_size_m;
  std::string not_again;
  if (moved_m > quarter_voxel_m) not_again = why_sessions_cannot_be_read(saved, config);
  const bool again = moved_m > quarter_voxel_m && not_again.empty();

  char placement_text[200];
  std::snprintf(placement_text, sizeof placement_text,
                "relocalized: keyframe %zu matched session %u keyframe %u (fitness %.1f mm, %zu "
                "keyframes agreeing); %zu links to earlier sessions",
                placement.keyframe, matched.session, matched.index, 1000.0 * placement.fitness_m,
                placement.agreeing, linked.links.size());
  SessionDescription session = request.session;
  session.placement = placement_text;

  report["placed"] = true;
  report["session"] = session_id;
  report["keyframe"] = placement.keyframe;
  report["seconds_in"] =
      static_cast<double>(placement.stamp_ns - loops.before.stamps_ns.front()) * 1e-9;
  report["matched"] = {{"session", matched.session}, {"index", matched.index}};
  report["found_by"] = placement.found_by;
  report["descriptor_distance"] = placement.descriptor_distance;
  report["fitness_m"] = placement.fitness_m;
  report["inlier_fraction"] = placement.inlier_fraction;
  report["agreeing"] = placement.agreeing;
  report["T_map_session"] = pose_json(placement.T_map_session);
  report["links"] = session_links_json(linked, keyframes);
  report["earlier_sessions"] = {
      {"moved_max_m", moved_m}, {"moved_max_deg", moved_deg}, {"mapped_again", again}};
  if (moved_m <= quarter_voxel_m) {
    report["earlier_sessions"]["why"] = "no keyframe moved more than a quarter voxel";
  } else if (!again) {
    report["earlier_sessions"]["why"] = not_again + ": the earlier map stays as it was";
    spdlog::warn(
        "the links moved the map's keyframes by up to {:.1f} mm, but {}: the earlier map "
        "stays as it was",
        1000.0 * moved_m, not_again);
  }

  if (!pipeline.integrate) {
    // --poses-only: placed, and nothing written into any map.
    run.pass.result = run.first;
    run.pass.result.poses = run.final_poses;
    run.second_pass = "--poses-only: placed, no map";
    return run;
  }
  // The mapping pass(es): this recording with its final poses, deskewed as the odometry
  // placed each scan; before it, where they moved, every earlier session again.
  PipelineSettings replay = pipeline;
  replay.refine.reset();
  replay.loops.reset();
  replay.relocalize.reset();
  replay.integrate = true;
  const auto this_recording = [&](const fs::path& into, const std::optional<std::string>& from,
                                  bool overwrite) {
    const std::unique_ptr<slam::ScanSource> source_again = reopen();
    const std::unique_ptr<slam::ScanLocator> locator =
        config.odometry.deskew ? slam::make_replay_locator(run.final_poses, run.first.scan_motions)
                               : slam::make_given_pose_locator(run.final_poses, false);
    const std::vector<slam::loops::KeyframeRecord> records =
        records_of(keyframes, first_new, keyframes.size(), linked.poses);
    return run_map_pass(*source_again, *locator, replay, config,
                        {into, request.sensor_name, from, overwrite, session, &records});
  };
  if (!again) {
    spdlog::info("mapping {} into {} with its poses in the map", request.session.input,
                 request.old_map.string());
    run.pass = this_recording(map_out, request.old_map.string(), request.overwrite);
    run.second_pass = "mapped into the saved map with the placed, corrected poses";
    return run;
  }
  const fs::path rebuilt = request.out / "map.rebuilt.h5";
  try {
    build_then_replace(rebuilt, map_out, [&] {
      remap_sessions(
          session_remaps(saved, keyframes, 0, 0, Eigen::Isometry3d::Identity(), linked.poses,
                         "; moved by the links of session " + std::to_string(session_id)),
          rebuilt, replay, config, request.sensor_name);
      run.pass = this_recording(rebuilt, rebuilt.string(), true);
      if (run.pass.result.interrupted) throw Interrupted("interrupted");
    });
  } catch (const Interrupted&) {
    throw Interrupted("interrupted while the map was made again; " + request.old_map.string() +
                      " is unchanged");
  }
  run.second_pass = "every session mapped again with the corrected poses";
  return run;
}

}  // namespace featsense::app
