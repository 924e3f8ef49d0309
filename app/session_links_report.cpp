#include "session_links_report.hpp"

#include <map>
#include <string>

namespace featsense::app {

namespace {

/// A keyframe by session and index, where the linked graph put it.
nlohmann::json keyframe_json(const slam::loops::MapKeyframe& keyframe,
                             const Eigen::Isometry3d& pose) {
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

}  // namespace

nlohmann::json session_links_json(const slam::loops::SessionLinkResult& linked,
                                  const std::vector<slam::loops::MapKeyframe>& keyframes) {
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

}  // namespace featsense::app
