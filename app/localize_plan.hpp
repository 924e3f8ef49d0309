#pragma once
// The plan view of `featsense localize` (topdown.png): the saved map around the path, seen from
// above, with the scans' poses drawn by status, for report.html.

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>

#include "featsense/slam/trajectory/trajectory.hpp"
#include "localize_report.hpp"

namespace featsense::app {

/// Meshes the part of `run.map` within `margin_m` of the posed scans (the store opened read
/// only) and writes `folder`/topdown.png: red where localized, amber on odometry, gaps where
/// lost, the truth in blue where given. Returns the report's account of the picture, or of why
/// there is none (no scan was posed, nothing of the map lies there). Throws
/// std::runtime_error when the picture cannot be written.
nlohmann::json write_localize_plan(const LocalizeRun& run,
                                   const std::optional<slam::Trajectory>& truth,
                                   const std::filesystem::path& folder, double margin_m);

}  // namespace featsense::app
