#include "session_links_report.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "featsense/bench/measurements.hpp"

namespace featsense::app {

using bench::timing_json;

namespace {

/// A keyframe by session and index, where the linked graph put it.
nlohmann::json keyframe_json(const mapping::KeyframeId& keyframe, const Eigen::Isometry3d& pose) {
  const Eigen::Vector3d at = pose.translation();
  return {{"session", keyframe.session},
          {"keyframe", keyframe.index},
          {"stamp_ns", keyframe.stamp_ns},
          {"at", {at.x(), at.y(), at.z()}}};
}

/// Links whose final weight is below a half: the graph found them at odds with the rest.
size_t weak_links(const slam::loops::SessionLinkResult& linked) {
  size_t weak = 0;
  for (const slam::loops::SessionLink& link : linked.links) {
    if (link.weight < 0.5) ++weak;
  }
  return weak;
}

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

}  // namespace

nlohmann::json session_links_json(const mapping::SessionLinks& links) {
  const slam::loops::SessionLinkResult& linked = links.linked;
  const std::vector<mapping::KeyframeId>& keyframes = links.keyframes;
  std::map<std::string, size_t> between;
  nlohmann::json list = nlohmann::json::array();
  for (const slam::loops::SessionLink& link : linked.links) {
    ++between[std::to_string(link.from_session) + "-" + std::to_string(link.to_session)];
    list.push_back({{"from", keyframe_json(keyframes[link.from], linked.poses[link.from])},
                    {"to", keyframe_json(keyframes[link.to], linked.poses[link.to])},
                    {"fitness_m", link.fitness_m},
                    {"inlier_fraction", link.inlier_fraction},
                    {"weight", link.weight},
                    {"moved_m", link.moved_m},
                    {"moved_deg", link.moved_deg}});
  }
  return {{"count", linked.links.size()},
          {"between_sessions", between},
          {"candidates", linked.candidates},
          {"rejected", linked.rejected},
          {"weight_below_half", weak_links(linked)},
          {"unlinked_sessions", linked.unlinked_sessions},
          {"link_s", linked.link_ms / 1000.0},
          {"optimise_s", linked.optimise_ms / 1000.0},
          {"list", list}};
}

nlohmann::json tried_json(const slam::loops::RelocalizationCounts& counts) {
  return {{"keyframes", counts.keyframes},
          {"candidates", counts.candidates},
          {"verified", counts.verified},
          {"rejected", counts.rejected},
          {"keyframe_ms", timing_json(counts.keyframe_ms)}};
}

nlohmann::json relocalization_json(const mapping::RelocalizationReport& report) {
  nlohmann::json out = {{"map", report.map},
                        {"map_sessions", report.map_sessions},
                        {"map_keyframes", report.map_keyframes},
                        {"max_scans", report.max_scans},
                        {"tried", tried_json(report.tried)},
                        {"placed", report.placement.has_value()}};
  if (!report.placement) {
    out["why"] = report.why;
    return out;
  }
  const slam::loops::Relocalization& placement = *report.placement;
  out["session"] = report.session;
  out["keyframe"] = placement.keyframe;
  out["seconds_in"] = report.seconds_in;
  out["matched"] = {{"session", report.matched.session}, {"index", report.matched.index}};
  out["found_by"] = placement.found_by;
  out["descriptor_distance"] = placement.descriptor_distance;
  out["fitness_m"] = placement.fitness_m;
  out["inlier_fraction"] = placement.inlier_fraction;
  out["agreeing"] = placement.agreeing;
  out["T_map_session"] = pose_json(placement.T_map_session);
  out["links"] = session_links_json(report.links);
  out["earlier_sessions"] = {
      {"moved_max_m", report.earlier_moved_max_m},
      {"moved_max_deg", report.earlier_moved_max_deg},
      {"mapped_again", report.earlier.kind == mapping::EarlierSessions::kMappedAgain}};
  if (!report.earlier.reason.empty()) out["earlier_sessions"]["why"] = report.earlier.reason;
  if (report.reintegration)
    out["earlier_sessions"]["reintegration"] = reintegration_json(*report.reintegration);
  return out;
}

nlohmann::json reintegration_json(const mapping::ReintegrationCounts& counts) {
  nlohmann::json out = {{"whole", counts.whole},
                        {"scans", counts.scans},
                        {"scans_moved", counts.scans_moved},
                        {"scans_integrated_again", counts.scans_reintegrated},
                        {"chunks_before", counts.chunks_before},
                        {"chunks_made_again", counts.chunks_changed},
                        {"chunks_kept", counts.chunks_kept},
                        {"plan_s", counts.plan_s},
                        {"integrate_s", counts.reintegrate_s},
                        {"assemble_s", counts.assemble_s}};
  if (!counts.why.empty()) out["why_whole"] = counts.why;
  return out;
}

}  // namespace featsense::app
