#pragma once
// The front end's sections of report.json: what the odometry did (`odometry`), what the
// refinement did (`refine`) and the loops closed (`loops`).

#include <nlohmann/json.hpp>

#include <string>

#include "featsense/mapping/pass_result.hpp"
#include "featsense/slam/odometry/odometry_locator.hpp"

namespace featsense::app {

/// Whether the intensity image confirmed the edges, in words: the fusion is off by the config,
/// or where the scans had no intensity channel.
std::string intensity_fusion_text(const slam::odometry::OdometryCounts& counts, bool enabled);

nlohmann::json odometry_json(const slam::odometry::OdometryCounts& counts, bool fusion_enabled);

/// The refinement of a run that refined (run.unrefined_poses set): stretches, what was kept
/// and why, the corrections, the latency in scans and the times.
nlohmann::json refine_json(const mapping::PassResult& run,
                           const slam::refine::RefineSettings& settings);

/// The loop closure of a run: keyframes, candidates, what was rejected and why, each loop
/// accepted (the keyframes, their stamps, the fit, the correction it brought, its final
/// weight), the largest correction of a scan and the times.
nlohmann::json loops_json(const mapping::LoopOutcome& outcome, double finish_ms);

}  // namespace featsense::app
