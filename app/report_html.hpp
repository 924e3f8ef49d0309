#pragma once
// report.html beside report.json: the report as a page (viewer_export/html_report.hpp).

#include <nlohmann/json.hpp>

#include <filesystem>

namespace featsense::app {

/// The file name report.json gives the page under `html`.
inline constexpr const char* kReportHtml = "report.html";

/// Writes `out`/report.html from `report` and the pictures in `out`. Throws std::runtime_error
/// naming the file when it cannot be written.
void write_report_html(const std::filesystem::path& out, const nlohmann::json& report);

}  // namespace featsense::app
