#pragma once
// The sections of report.html, each from the report.json object; html_report.cpp puts them
// on the page.

#include <nlohmann/json.hpp>

#include <filesystem>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace featsense::viewer_export {

/// The value at `keys` below `json`, or nullptr where any of them is missing.
const nlohmann::json* json_at(const nlohmann::json& json, std::initializer_list<const char*> keys);

/// A JSON value as text: strings as they are, numbers to 4 significant digits.
std::string json_text(const nlohmann::json& value);

/// Metres as "12.3 mm" below 1 m, "1.23 m" above.
std::string length_text_mm(double metres);

/// Rows of a two-column table: a name and its value, as text.
using Rows = std::vector<std::pair<std::string, std::string>>;

/// The rows as a <table> of <th> names and <td> values, both escaped.
std::string rows_table(const Rows& rows);

/// Input, scans, duration, speed, trajectory and mesh scores, warnings.
std::string summary_section(const nlohmann::json& report);

/// The pictures the report names, embedded: plan view, mesh error, trajectory error.
std::string pictures_section(const nlohmann::json& report, const std::filesystem::path& folder);

/// Bar charts of each stage's total time and time per scan (median and p95).
std::string timing_section(const nlohmann::json& report);

/// The loop closure: counts, the loops closed, the candidates rejected and why.
std::string loops_section(const nlohmann::json& report);

/// A localization run's (`featsense localize`): the first fix, the share localized, the
/// losses, the error against the truth, the time per scan, the lost periods and events.
std::string localization_section(const nlohmann::json& report);

}  // namespace featsense::viewer_export
