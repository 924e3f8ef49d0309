// The summary of report.html, and the small JSON helpers every section uses.
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "featsense/viewer_export/html_text.hpp"
#include "internal/html_sections.hpp"

namespace featsense::viewer_export {
namespace {

double number_at(const nlohmann::json& json, std::initializer_list<const char*> keys) {
  const nlohmann::json* value = json_at(json, keys);
  return value && value->is_number() ? value->get<double>() : NAN;
}

void add(Rows& rows, const std::string& name, const nlohmann::json* value,
         const std::string& unit = "") {
  if (value && !value->is_null()) rows.emplace_back(name, json_text(*value) + unit);
}

/// "mean 12.3 mm, median 10.1 mm, p95 30.2 mm" of a mesh accuracy object.
std::string accuracy_text(const nlohmann::json& accuracy) {
  return "mean " + length_text_mm(number_at(accuracy, {"mean_abs"})) + ", median " +
         length_text_mm(number_at(accuracy, {"median"})) + ", p95 " +
         length_text_mm(number_at(accuracy, {"p95"}));
}

void add_trajectory(Rows& rows, const nlohmann::json& report) {
  const nlohmann::json* traj = json_at(report, {"eval", "traj"});
  if (!traj) return;
  rows.emplace_back("ATE (RMSE, aligned)",
                    length_text_mm(number_at(*traj, {"ape", "rmse"})) + " over " +
                        json_text(number_at(*traj, {"ape", "count"})) + " poses, " +
                        number_text(number_at(*traj, {"ground_truth_length_m"})) + " m of path");
  if (const nlohmann::json* before = json_at(report, {"eval", "traj_before_loops"}))
    rows.emplace_back("ATE before the loops", length_text_mm(number_at(*before, {"ape", "rmse"})));
  if (const nlohmann::json* unrefined = json_at(report, {"eval", "traj_unrefined"}))
    rows.emplace_back("ATE of the odometry alone",
                      length_text_mm(number_at(*unrefined, {"ape", "rmse"})));
}

void add_mesh(Rows& rows, const nlohmann::json& report) {
  add(rows, "mesh triangles", json_at(report, {"mesh", "triangles"}));
  const nlohmann::json* mesh = json_at(report, {"eval", "mesh"});
  if (!mesh) return;
  if (const nlohmann::json* accuracy = json_at(*mesh, {"accuracy"}))
    rows.emplace_back("mesh accuracy, as mapped", accuracy_text(*accuracy));
  if (const nlohmann::json* aligned = json_at(*mesh, {"aligned", "accuracy"}))
    rows.emplace_back("mesh accuracy, path aligned", accuracy_text(*aligned));
  if (const nlohmann::json* completeness = json_at(*mesh, {"completeness"})) {
    std::string text;
    for (const auto& [key, value] : completeness->items()) {
      if (!value.is_number()) continue;
      char part[64];
      std::snprintf(part, sizeof(part), "%s%.1f %% within %s m", text.empty() ? "" : ", ",
                    100.0 * value.get<double>(), key.c_str());
      text += part;
    }
    if (!text.empty()) rows.emplace_back("mesh completeness", text);
  }
}

std::string warnings_block(const nlohmann::json& report) {
  const nlohmann::json* first = json_at(report, {"warnings", "first"});
  if (!first || !first->is_array() || first->empty()) return "";
  std::string html = "<ul class=\"warning\">\n";
  for (const nlohmann::json& warning : *first)
    html += "<li>" + html_escape(json_text(warning)) + "</li>\n";
  return html + "</ul>\n";
}

}  // namespace

const nlohmann::json* json_at(const nlohmann::json& json, std::initializer_list<const char*> keys) {
  const nlohmann::json* at = &json;
  for (const char* key : keys) {
    if (!at->is_object()) return nullptr;
    const auto found = at->find(key);
    if (found == at->end()) return nullptr;
    at = &*found;
  }
  return at;
}

std::string json_text(const nlohmann::json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_float()) return number_text(value.get<double>());
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string length_text_mm(double metres) {
  if (!std::isfinite(metres)) return "-";
  char text[32];
  if (std::abs(metres) < 1.0) {
    std::snprintf(text, sizeof(text), "%.1f mm", metres * 1e3 + 0.0);
  } else {
    std::snprintf(text, sizeof(text), "%.3g m", metres);
  }
  return text;
}

std::string rows_table(const Rows& rows) {
  std::string html = "<table>\n";
  for (const auto& [name, value] : rows)
    html += "<tr><th>" + html_escape(name) + "</th><td>" + html_escape(value) + "</td></tr>\n";
  return html + "</table>\n";
}

std::string summary_section(const nlohmann::json& report) {
  Rows rows;
  if (const nlohmann::json* input = json_at(report, {"input"})) {
    add(rows, "input", json_at(*input, {"path"}));
    add(rows, "format", json_at(*input, {"format"}));
    add(rows, "sensor", json_at(*input, {"sensor"}));
  }
  add(rows, "scans mapped", json_at(report, {"frames"}));
  add(rows, "scans read", json_at(report, {"frames_read"}));
  add(rows, "recording", json_at(report, {"recording_s"}), " s");
  add(rows, "mapping time", json_at(report, {"wall_s"}), " s");
  add(rows, "speed", json_at(report, {"scans_per_s"}), " scans/s");
  add(rows, "real-time factor", json_at(report, {"real_time_factor"}));
  add(rows, "poses", json_at(report, {"poses"}));
  add(rows, "backend", json_at(report, {"backend"}));
  add(rows, "peak memory", json_at(report, {"peak_rss_mb"}), " MB");
  add(rows, "interrupted", json_at(report, {"interrupted"}));
  add_trajectory(rows, report);
  add_mesh(rows, report);
  add(rows, "warnings", json_at(report, {"warnings", "count"}));

  return "<h2>Summary</h2>\n" + rows_table(rows) + warnings_block(report);
}

}  // namespace featsense::viewer_export
