#pragma once
// The `links` section of a continued run's or a merge's report: how many links joined the
// sessions, between which, what was tried and rejected, and each link by name (which keyframe
// of which session saw which, its fit, its final weight in the graph and how far it moved the
// later session when it was accepted), so that a user can see where the sessions were joined.

#include <nlohmann/json.hpp>

#include <vector>

#include "featsense/slam/loops/map_keyframe.hpp"
#include "featsense/slam/loops/session_links.hpp"

namespace featsense::app {

/// `keyframes`: those given to link_sessions, in the same order.
nlohmann::json session_links_json(const slam::loops::SessionLinkResult& linked,
                                  const std::vector<slam::loops::MapKeyframe>& keyframes);

}  // namespace featsense::app
