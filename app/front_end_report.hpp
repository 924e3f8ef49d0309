#pragma once
// The front end's sections of report.json: what the odometry did (`odometry`) and what the
// refinement did (`refine`).

#include <nlohmann/json.hpp>

#include <string>

#include "featsense/slam/odometry/odometry_locator.hpp"
#include "map_pipeline.hpp"

namespace featsense::app {

/// Whether the intensity image confirmed the edges, in words: the fusion is off by the config,
/// or where the scans had no intensity channel.
std::string intensity_fusion_text(const slam::odometry::OdometryCounts& counts, bool enabled);

nlohmann::json odometry_json(const slam::odometry::OdometryCounts& counts, bool fusion_enabled);

/// The refinement of a run that refined (run.unrefined_poses set): stretches, what was kept
/// and why, the corrections, the latency in scans and the times.
nlohmann::json refine_json(const PipelineResult& run, const slam::refine::RefineSettings& settings);

}  // namespace featsense::app
