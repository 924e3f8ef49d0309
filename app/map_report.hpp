#pragma once
// report.json of `featsense map` and `featsense demo` (keys in DESIGN.md, "Names that
// scripts rely on"): what went in, what came out, how long each stage took.

#include <nlohmann/json.hpp>

#include <filesystem>

#include "featsense/config/config.hpp"
#include "featsense/mapping/mapper.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::app {

/// The report of a run of `config` over `input`; the front end's, `eval` and `mesh` sections
/// are added by the caller where there are some.
nlohmann::json map_report_json(const config::Config& config, const slam::SourceInfo& input,
                               const mapping::MapResult& result);

/// The sessions of the map at `path` for the report: each with its input, format, scans,
/// stamps, placement and the number of keyframes it keeps.
nlohmann::json sessions_json(const std::filesystem::path& path);

}  // namespace featsense::app
