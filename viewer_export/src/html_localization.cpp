// The localization part of report.html, for `featsense localize`'s report: when and where the
// sensor was found, how much of the run it was localized, when it was lost and why, the error
// against the truth where one was given, and the time per scan.
#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "featsense/viewer_export/html_text.hpp"
#include "internal/html_sections.hpp"

namespace featsense::viewer_export {
namespace {

/// Rows shown in a list (events, lost periods) at most: the report holds them all.
constexpr size_t kMaxListRows = 50;

std::string text_at(const nlohmann::json& json, std::initializer_list<const char*> keys,
                    const std::string& unit = "") {
  const nlohmann::json* value = json_at(json, keys);
  return value && !value->is_null() ? json_text(*value) + unit : "-";
}

std::string percent_text(const nlohmann::json* share) {
  if (!share || !share->is_number()) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.1f %%", 100.0 * share->get<double>());
  return text;
}

/// "found after 7.0 s (scan 70) by keyframes, at (12.1, -3.4, 1.9)".
std::string first_fix_text(const nlohmann::json& fix) {
  std::string text = "after " + text_at(fix, {"seconds_in"}, " s") + " of the input (scan " +
                     text_at(fix, {"scan"}) + "), by " + text_at(fix, {"found_by"});
  const nlohmann::json* position = json_at(fix, {"position"});
  if (position && position->is_array() && position->size() == 3) {
    char where[96];
    std::snprintf(where, sizeof where, ", at (%.1f, %.1f, %.1f) m", (*position)[0].get<double>(),
                  (*position)[1].get<double>(), (*position)[2].get<double>());
    text += where;
  }
  return text;
}

std::string counts_text(const nlohmann::json* counts) {
  if (!counts || !counts->is_object() || counts->empty()) return "none";
  std::string text;
  for (const auto& [reason, count] : counts->items())
    text += (text.empty() ? "" : ", ") + json_text(count) + " " + reason;
  return text;
}

std::string summary_table(const nlohmann::json& loc) {
  Rows rows;
  const nlohmann::json* found = json_at(loc, {"localized"});
  const bool ever = found && found->is_boolean() && found->get<bool>();
  rows.emplace_back("found in the map", ever ? "yes" : "no: no pose was given");
  if (const nlohmann::json* fix = json_at(loc, {"first_fix"})) {
    rows.emplace_back("first fix", first_fix_text(*fix));
    rows.emplace_back("localized after the first fix",
                      percent_text(json_at(loc, {"localized_share_after_first_fix"})));
  }
  rows.emplace_back("scans localized", text_at(loc, {"scans", "localized"}));
  rows.emplace_back("scans on odometry", text_at(loc, {"scans", "odometry"}));
  rows.emplace_back("scans lost", text_at(loc, {"scans", "lost"}));
  rows.emplace_back("times found", text_at(loc, {"fixes"}));
  rows.emplace_back("times lost", counts_text(json_at(loc, {"losses"})));
  if (const nlohmann::json* search = json_at(loc, {"search"})) {
    rows.emplace_back("the search: keyframes matched",
                      text_at(*search, {"keyframes"}) + " (" + text_at(*search, {"candidates"}) +
                          " candidates, " + text_at(*search, {"verified"}) + " verified)");
    rows.emplace_back("the search: why a keyframe placed nothing",
                      counts_text(json_at(*search, {"rejected"})));
  }
  rows.emplace_back("keyframe matches the surface refuted", text_at(loc, {"unconfirmed_matches"}));
  return rows_table(rows);
}

/// The resident memory as the input went on: where it began, where it ended, its peak.
std::string memory_text(const nlohmann::json& samples) {
  if (!samples.is_array() || samples.empty()) return "-";
  double peak = 0.0;
  for (const nlohmann::json& s : samples) peak = std::max(peak, s.value("rss_mb", 0.0));
  const nlohmann::json& first = samples.front();
  const nlohmann::json& last = samples.back();
  char text[160];
  std::snprintf(text, sizeof text, "%.0f MB at %.0f s of input, %.0f MB at %.0f s, at most %.0f MB",
                first.value("rss_mb", 0.0), first.value("input_s", 0.0), last.value("rss_mb", 0.0),
                last.value("input_s", 0.0), peak);
  return text;
}

std::string spread_text(const nlohmann::json* spread, double scale, const char* unit) {
  if (!spread || !spread->is_object()) return "-";
  char text[160];
  const auto at = [&](const char* key) {
    const nlohmann::json* v = json_at(*spread, {key});
    return v && v->is_number() ? scale * v->get<double>() : 0.0;
  };
  std::snprintf(text, sizeof text, "median %.3g %s, p95 %.3g %s, max %.3g %s (%g poses)",
                at("median"), unit, at("p95"), unit, at("max"), unit, at("count") / scale);
  return text;
}

std::string truth_table(const nlohmann::json& report) {
  const nlohmann::json* eval = json_at(report, {"eval"});
  if (!eval || !eval->is_object()) return "";
  Rows rows;
  for (const char* status : {"localized", "odometry"}) {
    const nlohmann::json* errors = json_at(*eval, {status});
    if (!errors) continue;
    rows.emplace_back(std::string(status) + ": position",
                      spread_text(json_at(*errors, {"translation_m"}), 100.0, "cm"));
    rows.emplace_back(std::string(status) + ": heading and tilt",
                      spread_text(json_at(*errors, {"rotation_deg"}), 1.0, "deg"));
  }
  rows.emplace_back("localized poses off by more than 0.5 m",
                    text_at(*eval, {"localized_over_0_5_m"}));
  return "<h3>Against the truth</h3>\n<p>Each pose against the true one at its time, in the "
         "map's frame, without any alignment.</p>\n" +
         rows_table(rows);
}

std::string timing_text(const nlohmann::json* timing) {
  if (!timing || !timing->is_object()) return "-";
  return "median " + text_at(*timing, {"median_ms"}, " ms") + ", p95 " +
         text_at(*timing, {"p95_ms"}, " ms") + ", max " + text_at(*timing, {"max_ms"}, " ms") +
         " (" + text_at(*timing, {"count"}) + " scans)";
}

std::string timing_table(const nlohmann::json& report) {
  const nlohmann::json* timings = json_at(report, {"timings"});
  if (!timings) return "";
  Rows rows;
  rows.emplace_back("tracking (a localized scan)", timing_text(json_at(*timings, {"tracking"})));
  for (const char* part : {"odometry", "cloud", "register"})
    rows.emplace_back(std::string("  of which ") + part,
                      timing_text(json_at(*timings, {"tracking_parts", part})));
  rows.emplace_back("searching (a scan while lost)", timing_text(json_at(*timings, {"search"})));
  rows.emplace_back("searching in all", text_at(*timings, {"search_total_s"}, " s"));
  rows.emplace_back("every scan", timing_text(json_at(*timings, {"per_scan"})));
  if (const nlohmann::json* memory = json_at(report, {"rss_mb_over_input"}))
    rows.emplace_back("resident memory", memory_text(*memory));
  return "<h3>Time per scan, and memory</h3>\n" + rows_table(rows);
}

std::string lost_periods_table(const nlohmann::json& loc) {
  const nlohmann::json* periods = json_at(loc, {"lost_periods"});
  if (!periods || !periods->is_array() || periods->empty()) return "";
  std::string html =
      "<h3>Lost after the first fix</h3>\n<table>\n<tr><th>from</th><th>for</th><th>scans</th>"
      "<th>found again</th></tr>\n";
  size_t shown = 0;
  for (const nlohmann::json& period : *periods) {
    if (++shown > kMaxListRows) break;
    html += "<tr><td class=\"num\">" + html_escape(text_at(period, {"from_s"}, " s")) +
            "</td><td class=\"num\">" + html_escape(text_at(period, {"seconds"}, " s")) +
            "</td><td class=\"num\">" + html_escape(text_at(period, {"scans"})) + "</td><td>" +
            html_escape(text_at(period, {"found_again"})) + "</td></tr>\n";
  }
  html += "</table>\n";
  if (periods->size() > kMaxListRows)
    html += "<p>... and " + std::to_string(periods->size() - kMaxListRows) + " more.</p>\n";
  return html;
}

std::string events_list(const nlohmann::json& loc) {
  const nlohmann::json* events = json_at(loc, {"events"});
  if (!events || !events->is_array() || events->empty()) return "";
  std::string html =
      "<h3>What happened</h3>\n<table>\n<tr><th>time</th><th>scan</th><th>event</th></tr>\n";
  size_t shown = 0;
  for (const nlohmann::json& event : *events) {
    if (++shown > kMaxListRows) break;
    html += "<tr><td class=\"num\">" + html_escape(text_at(event, {"t_s"}, " s")) +
            "</td><td class=\"num\">" + html_escape(text_at(event, {"scan"})) + "</td><td>" +
            html_escape(text_at(event, {"event"})) + "</td></tr>\n";
  }
  html += "</table>\n";
  const nlohmann::json* count = json_at(loc, {"event_count"});
  if (count && count->is_number() && count->get<double>() > static_cast<double>(kMaxListRows))
    html += "<p>" + html_escape(json_text(*count)) + " events in all: report.json has them.</p>\n";
  return html;
}

}  // namespace

std::string localization_section(const nlohmann::json& report) {
  const nlohmann::json* loc = json_at(report, {"localization"});
  if (!loc || !loc->is_object()) return "";
  std::string html = "<h2>Localization</h2>\n" + summary_table(*loc);
  if (const nlohmann::json* why = json_at(*loc, {"plan", "why_not"}))
    html += "<p>No plan view: " + html_escape(json_text(*why)) + ".</p>\n";
  html += truth_table(report);
  html += timing_table(report);
  html += lost_periods_table(*loc);
  html += events_list(*loc);
  return html;
}

}  // namespace featsense::viewer_export
