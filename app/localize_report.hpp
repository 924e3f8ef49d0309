#pragma once
// What `featsense localize` writes: trajectory.tum (every scan with a pose in the map's frame,
// localized or on odometry), localization.csv (every scan: its status, pose and fit) and
// report.json (when and where the sensor was found, how long it was lost, the fit and time
// per scan, the map's cache; the error against a given truth).

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/mapping/localizer.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::app {

struct LocalizeRun {
  std::string map;
  slam::SourceInfo input;
  std::vector<mapping::LocalizedScan> scans;
  mapping::LocalizerCounts counts;
  bool interrupted = false;
  double wall_s = 0.0;
  size_t frames_skipped = 0;
  size_t warnings = 0;
};

/// The poses of the scans that have one (localized or on odometry).
slam::Trajectory posed_path(const std::vector<mapping::LocalizedScan>& scans);

/// Writes trajectory.tum and localization.csv into `folder`.
void write_localization_files(const LocalizeRun& run, const std::filesystem::path& folder);

/// The report; with `truth` (poses in the map's frame) each posed scan's error too.
nlohmann::json localize_report_json(const config::Config& config, const LocalizeRun& run,
                                    const std::optional<slam::Trajectory>& truth);

}  // namespace featsense::app
