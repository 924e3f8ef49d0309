#include "featsense/viewer_export/html_report.hpp"

#include "featsense/viewer_export/html_text.hpp"
#include "internal/html_sections.hpp"

namespace featsense::viewer_export {
namespace {

// The page's whole style: system fonts only, so that nothing is fetched.
constexpr const char* kStyle = R"(
body { font-family: sans-serif; margin: 1.5em auto; max-width: 1100px; color: #222; padding: 0 1em; }
h1 { font-size: 1.6em; } h2 { font-size: 1.25em; border-bottom: 1px solid #ccc; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.5em 0; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #f2f2f2; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
figure { margin: 1em 0; } figure img { max-width: 100%; height: auto; border: 1px solid #ccc; }
figcaption { color: #555; font-size: 0.9em; }
pre { background: #f7f7f7; border: 1px solid #ddd; padding: 0.6em; overflow: auto; font-size: 0.85em; }
svg.chart { display: block; margin: 0.8em 0; font-family: sans-serif; font-size: 12px; }
svg.chart .bar { fill: #3b78c3; } svg.chart .chart-title { font-weight: bold; font-size: 13px; }
.warning { color: #a33; }
)";

/// The config as the report holds it: YAML text, or an object, pretty-printed.
std::string config_section(const nlohmann::json& report) {
  const nlohmann::json* config = json_at(report, {"config"});
  if (!config) return "";
  const std::string text =
      config->is_string() ? config->get<std::string>()
                          : config->dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  return "<h2>Config used</h2>\n<pre>" + html_escape(text) + "</pre>\n";
}

std::string raw_report_section(const nlohmann::json& report) {
  return "<h2>report.json</h2>\n<details><summary>Every figure of the run</summary>\n<pre>" +
         html_escape(report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace)) +
         "</pre></details>\n";
}

}  // namespace

std::string html_report(const nlohmann::json& report, const std::filesystem::path& folder) {
  // A localization run's report (`featsense localize`) or a mapping run's.
  const bool localization = json_at(report, {"localization"}) != nullptr;
  std::string title = localization ? "featsense localization report" : "featsense map report";
  if (const nlohmann::json* input = json_at(report, {"input", "path"}))
    title += ": " + json_text(*input);
  std::string page = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  page += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  page += "<title>" + html_escape(title) + "</title>\n<style>" + kStyle + "</style>\n</head>\n";
  page += "<body>\n<h1>" + html_escape(title) + "</h1>\n";
  page += summary_section(report);
  if (localization) {
    page += localization_section(report);
    page += pictures_section(report, folder);
  } else {
    page += pictures_section(report, folder);
    page += timing_section(report);
    page += loops_section(report);
  }
  page += config_section(report);
  page += raw_report_section(report);
  page += "</body>\n</html>\n";
  return page;
}

}  // namespace featsense::viewer_export
