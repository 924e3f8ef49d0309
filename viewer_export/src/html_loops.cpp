// The loops of report.html: what loop_stage / front_end_report wrote under `loops`.
#include <utility>
#include <vector>

#include "featsense/viewer_export/html_text.hpp"
#include "internal/html_sections.hpp"

namespace featsense::viewer_export {
namespace {

std::string cell(const nlohmann::json* value, bool number) {
  const std::string text = value ? json_text(*value) : "-";
  return std::string(number ? "<td class=\"num\">" : "<td>") + html_escape(text) + "</td>";
}

std::string counts_table(const nlohmann::json& loops) {
  const std::pair<const char*, const char*> counts[] = {
      {"keyframes", "keyframes"},         {"candidates", "candidates"},
      {"verified", "verified"},           {"accepted", "loops closed"},
      {"optimisations", "optimisations"}, {"max_scan_correction_m", "largest scan correction, m"},
      {"second_pass", "the map"}};
  std::string html = "<table>\n";
  for (const auto& [key, name] : counts) {
    const nlohmann::json* value = json_at(loops, {key});
    if (!value) continue;
    html += "<tr><th>" + html_escape(name) + "</th>" + cell(value, value->is_number()) + "</tr>\n";
  }
  return html + "</table>\n";
}

std::string loops_table(const nlohmann::json& list) {
  if (!list.is_array() || list.empty()) return "<p>No loop was closed.</p>\n";
  const std::pair<const char*, const char*> columns[] = {{"keyframe", "keyframe"},
                                                         {"revisits_keyframe", "revisits keyframe"},
                                                         {"time_s", "time, s"},
                                                         {"revisits_time_s", "revisits time, s"},
                                                         {"found_by", "found by"},
                                                         {"fitness_m", "fitness, m"},
                                                         {"inlier_fraction", "inliers"},
                                                         {"correction_m", "correction, m"},
                                                         {"correction_deg", "correction, deg"}};
  std::string html = "<table>\n<tr>";
  for (const auto& [key, name] : columns) html += "<th>" + html_escape(name) + "</th>";
  html += "</tr>\n";
  for (const nlohmann::json& loop : list) {
    html += "<tr>";
    for (const auto& [key, name] : columns) {
      const nlohmann::json* value = json_at(loop, {key});
      html += cell(value, value && value->is_number());
    }
    html += "</tr>\n";
  }
  return html + "</table>\n";
}

std::string rejections_table(const nlohmann::json* rejected) {
  if (!rejected || !rejected->is_object() || rejected->empty()) return "";
  std::string html = "<h3>Candidates rejected</h3>\n<table>\n<tr><th>why</th><th>count</th></tr>\n";
  for (const auto& [reason, count] : rejected->items())
    html += "<tr><td>" + html_escape(reason) + "</td>" + cell(&count, true) + "</tr>\n";
  return html + "</table>\n";
}

}  // namespace

std::string loops_section(const nlohmann::json& report) {
  const nlohmann::json* loops = json_at(report, {"loops"});
  if (!loops || !loops->is_object()) return "";
  std::string html = "<h2>Loop closure</h2>\n";
  const nlohmann::json* enabled = json_at(*loops, {"enabled"});
  if (enabled && enabled->is_boolean() && !enabled->get<bool>()) {
    const nlohmann::json* why = json_at(*loops, {"why"});
    return html + "<p>Off" + (why ? ": " + html_escape(json_text(*why)) : std::string()) +
           ".</p>\n";
  }
  html += counts_table(*loops);
  if (const nlohmann::json* list = json_at(*loops, {"loops"})) html += loops_table(*list);
  return html + rejections_table(json_at(*loops, {"rejected"}));
}

}  // namespace featsense::viewer_export
