// The timing charts of report.html: every timing summary the report holds (timing_json's
// count / median_ms / p95_ms / total_s), per stage.
#include <vector>

#include "featsense/viewer_export/html_text.hpp"
#include "featsense/viewer_export/svg_bar_chart.hpp"
#include "internal/html_sections.hpp"

namespace featsense::viewer_export {
namespace {

struct StageTiming {
  std::string label;
  const nlohmann::json* summary;
};

/// The summaries under `timings` (those with samples), labelled "`prefix` `stage`".
void collect(const nlohmann::json* timings, const std::string& prefix,
             std::vector<StageTiming>& stages) {
  if (!timings || !timings->is_object()) return;
  for (const auto& [stage, summary] : timings->items()) {
    if (!summary.is_object() || !summary.contains("median_ms")) continue;
    const nlohmann::json* count = json_at(summary, {"count"});
    if (count && count->is_number() && count->get<double>() == 0.0) continue;
    stages.push_back({prefix.empty() ? stage : prefix + " " + stage, &summary});
  }
}

std::string chart(const std::vector<StageTiming>& stages, const std::string& title, const char* key,
                  const std::string& unit) {
  BarChart chart;
  chart.title = title;
  chart.unit = unit;
  for (const StageTiming& stage : stages) {
    const nlohmann::json* value = json_at(*stage.summary, {key});
    chart.bars.push_back({stage.label, value && value->is_number() ? value->get<double>() : 0.0});
  }
  return svg_bar_chart(chart);
}

}  // namespace

std::string timing_section(const nlohmann::json& report) {
  std::vector<StageTiming> pipeline;
  collect(json_at(report, {"timings"}), "", pipeline);
  std::vector<StageTiming> front_end;
  collect(json_at(report, {"odometry", "timings"}), "odometry", front_end);
  collect(json_at(report, {"refine", "timings"}), "refine", front_end);
  collect(json_at(report, {"loops", "timings"}), "loops", front_end);
  if (pipeline.empty() && front_end.empty()) return "";

  std::string html = "<h2>Where the time went</h2>\n";
  html +=
      "<p>Each stage of the pipeline runs in a thread of its own: their times overlap, and "
      "the slowest sets the pace.</p>\n";
  if (!pipeline.empty()) {
    html += chart(pipeline, "Pipeline stages: total time", "total_s", "s");
    html += chart(pipeline, "Pipeline stages: median time per call", "median_ms", "ms");
    html += chart(pipeline, "Pipeline stages: p95 time per call", "p95_ms", "ms");
  }
  if (!front_end.empty()) {
    html += chart(front_end, "Front end: total time", "total_s", "s");
    html += chart(front_end, "Front end: median time per call", "median_ms", "ms");
  }
  return html;
}

}  // namespace featsense::viewer_export
