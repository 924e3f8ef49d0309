#pragma once
// report.html: a mapping or localization run's report.json as one page that opens offline in any
// browser. Everything is inside the file: pictures as base64 data URIs, charts as inline SVG,
// styles inline; no scripts, no fonts, no addresses.

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace featsense::viewer_export {

/// The page for `report` (the object of report.json, keys in DESIGN.md): the summary, the
/// pictures it names that lie in `folder` (topdown.png, mesh_error.png,
/// trajectory_error.png), the timing charts, the loops, the config and the whole report.
/// Every text taken from the report is escaped.
std::string html_report(const nlohmann::json& report, const std::filesystem::path& folder);

}  // namespace featsense::viewer_export
