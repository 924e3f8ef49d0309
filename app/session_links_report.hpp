#pragma once
// The relocalization and the links between sessions as report.json writes them: where a
// recording was placed in a saved map and by which keyframes, each link between two
// sessions' keyframes (which keyframes, where the linked graph put them, the fit, the final
// weight and how far the link moved the session when it was found), and what became of the
// map's earlier sessions (`featsense map --continue` and `featsense merge`).

#include <nlohmann/json.hpp>

#include "featsense/mapping/relocalization_report.hpp"
#include "featsense/mapping/session_remap.hpp"
#include "featsense/slam/loops/relocalizer.hpp"

namespace featsense::app {

nlohmann::json session_links_json(const mapping::SessionLinks& links);

/// What placing tried: keyframes, candidates, verified, rejections by reason, times.
nlohmann::json tried_json(const slam::loops::RelocalizationCounts& counts);

/// report.json's "relocalization" of `featsense map --continue`.
nlohmann::json relocalization_json(const mapping::RelocalizationReport& report);

/// What was integrated again where earlier sessions were mapped again, and what was kept.
nlohmann::json reintegration_json(const mapping::ReintegrationCounts& counts);

}  // namespace featsense::app
