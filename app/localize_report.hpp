#pragma once
// The report of `featsense localize` (trajectory.tum and localization.csv are written as it
// goes: localization_files.hpp): report.json (when and where the sensor was found, how long it was
// lost, the fit and time per scan, the map's cache; the error against a given truth).

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
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
  /// The resident memory as the input went on: (seconds of input, MiB), every half minute.
  std::vector<std::pair<double, double>> rss_mb;
};

/// The report; with `truth` (poses in the map's frame) each posed scan's error too.
nlohmann::json localize_report_json(const config::Config& config, const LocalizeRun& run,
                                    const std::optional<slam::Trajectory>& truth);

}  // namespace featsense::app
