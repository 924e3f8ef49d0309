// report.html from a report.json object: self-contained (pictures as data URIs, no address
// of anything), every text escaped, the sections the report has.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "common/test_data.hpp"
#include "featsense/viewer_export/base64.hpp"
#include "featsense/viewer_export/html_report.hpp"

namespace featsense::viewer_export {
namespace {

namespace fs = std::filesystem;

/// A report as `featsense map` writes one, with text that must not reach the page raw.
nlohmann::json sample_report() {
  nlohmann::json timing = {{"count", 10},   {"median_ms", 2.0}, {"p95_ms", 3.0},
                           {"max_ms", 4.0}, {"mean_ms", 2.5},   {"total_s", 0.025}};
  nlohmann::json report;
  report["input"] = {{"path", "rec<1>.pcap"}, {"format", "pcap"}, {"sensor", "os1-64"}};
  report["frames"] = 10;
  report["wall_s"] = 1.5;
  report["recording_s"] = 1.0;
  report["timings"] = {{"read", timing}, {"integrate", timing}, {"flush", {{"count", 0}}}};
  report["timings"]["integrate"]["total_s"] = 0.1;
  report["mesh"] = {{"triangles", 1234}, {"plan", {{"file", "topdown.png"}}}};
  report["eval"]["traj"] = {{"ape", {{"rmse", 0.0123}, {"count", 10}}},
                            {"ground_truth_length_m", 12.0},
                            {"error_files", {{"png", "trajectory_error.png"}}}};
  report["eval"]["mesh"] = {{"accuracy", {{"mean_abs", 0.02}, {"median", 0.015}, {"p95", 0.05}}},
                            {"error_files", {{"png", "../../etc/mesh_error.png"}}}};
  report["loops"] = {
      {"keyframes", 12},
      {"candidates", 3},
      {"accepted", 1},
      {"rejected", {{"fit <worse>", 2}}},
      {"loops",
       {{{"keyframe", 11}, {"revisits_keyframe", 1}, {"fitness_m", 0.03}, {"correction_m", 0.2}}}},
      {"timings", {{"keyframe", timing}}}};
  report["warnings"] = {{"count", 1}, {"first", {"a <b>warning</b>"}}};
  report["config"] = "map:\n  note: \"</pre><script>alert('x')</script>\"\n";
  return report;
}

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

struct Page {
  fs::path folder;
  std::string html;
};

Page sample_page() {
  Page page;
  page.folder = test::scratch_dir("html_report");
  // Not real PNGs: the page carries the bytes as they are.
  write_file(page.folder / "topdown.png", "\x89PNG plan");
  write_file(page.folder / "trajectory_error.png", "\x89PNG trajectory");
  write_file(page.folder / "mesh_error.png", "\x89PNG mesh error");
  page.html = html_report(sample_report(), page.folder);
  return page;
}

TEST(HtmlReport, EmbedsThePicturesAsDataUris) {
  const Page page = sample_page();
  EXPECT_NE(page.html.find("src=\"data:image/png;base64," +
                           base64_encode(std::string("\x89PNG plan")) + "\""),
            std::string::npos);
  EXPECT_NE(
      page.html.find("data:image/png;base64," + base64_encode(std::string("\x89PNG trajectory"))),
      std::string::npos);
  // The report's name is taken as a file of the folder only: ../../etc/ is dropped.
  EXPECT_NE(
      page.html.find("data:image/png;base64," + base64_encode(std::string("\x89PNG mesh error"))),
      std::string::npos);
  // Every <img> is a data URI.
  const std::regex img("<img[^>]*src=\"([^\"]*)\"");
  int images = 0;
  for (auto it = std::sregex_iterator(page.html.begin(), page.html.end(), img);
       it != std::sregex_iterator(); ++it, ++images)
    EXPECT_EQ((*it)[1].str().rfind("data:image/png;base64,", 0), 0u);
  EXPECT_EQ(images, 3);
}

TEST(HtmlReport, LeavesOutPicturesThatAreNotThere) {
  const fs::path folder = test::scratch_dir("html_report_bare");
  const std::string html = html_report(sample_report(), folder);
  EXPECT_EQ(html.find("<img"), std::string::npos);
}

TEST(HtmlReport, NamesNoAddressAtAll) {
  const std::string html = sample_page().html;
  for (const char* reference : {"http://", "https://", "src=\"//", "href=\"//", "url(", "@import"})
    EXPECT_EQ(html.find(reference), std::string::npos) << reference;
  EXPECT_EQ(html.find("<script"), std::string::npos);  // no scripts at all
  EXPECT_EQ(html.find("<link"), std::string::npos);
}

TEST(HtmlReport, EscapesEveryTextOfTheReport) {
  const std::string html = sample_page().html;
  EXPECT_EQ(html.find("<script>alert"), std::string::npos);
  EXPECT_NE(html.find("&lt;/pre&gt;&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt;"),
            std::string::npos);
  EXPECT_EQ(html.find("<b>warning"), std::string::npos);
  EXPECT_NE(html.find("a &lt;b&gt;warning&lt;/b&gt;"), std::string::npos);
  EXPECT_NE(html.find("rec&lt;1&gt;.pcap"), std::string::npos);
  EXPECT_NE(html.find("fit &lt;worse&gt;"), std::string::npos);
}

TEST(HtmlReport, HasTheSummaryChartsLoopsAndConfig) {
  const std::string html = sample_page().html;
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<meta charset=\"utf-8\">"), std::string::npos);
  EXPECT_NE(html.find("12.3 mm"), std::string::npos);  // the ATE
  EXPECT_NE(html.find("mean 20.0 mm, median 15.0 mm, p95 50.0 mm"), std::string::npos);
  EXPECT_NE(html.find("<svg class=\"chart\""), std::string::npos);
  EXPECT_NE(html.find(">integrate<"), std::string::npos);
  EXPECT_NE(html.find(">loops keyframe<"), std::string::npos);
  EXPECT_EQ(html.find(">flush<"), std::string::npos);  // no samples, no bar
  EXPECT_NE(html.find("<h2>Loop closure</h2>"), std::string::npos);
  EXPECT_NE(html.find("<td class=\"num\">0.2</td>"), std::string::npos);  // the correction
  EXPECT_NE(html.find("<h2>Config used</h2>"), std::string::npos);
}

TEST(HtmlReport, ReadsAReportWithoutOptionalSections) {
  const std::string html =
      html_report(nlohmann::json{{"frames", 3}, {"loops", {{"enabled", false}, {"why", "given"}}}},
                  test::scratch_dir("html_report_small"));
  EXPECT_NE(html.find("Off: given."), std::string::npos);
  EXPECT_EQ(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("</html>"), std::string::npos);
}

/// A report as `featsense localize` writes one.
nlohmann::json localization_report() {
  const nlohmann::json timing = {{"count", 90},    {"median_ms", 30.0}, {"p95_ms", 40.0},
                                 {"max_ms", 50.0}, {"mean_ms", 31.0},   {"total_s", 2.8}};
  const nlohmann::json spread = {{"median", 0.01}, {"p95", 0.02}, {"max", 0.03}, {"count", 90}};
  nlohmann::json report;
  report["input"] = {{"path", "drive.bag"}, {"format", "rosbag"}};
  report["frames"] = 100;
  report["localization"] = {
      {"localized", true},
      {"first_fix",
       {{"scan", 7}, {"seconds_in", 0.7}, {"found_by", "descriptor"}, {"position", {1, 2, 3}}}},
      {"localized_share_after_first_fix", 0.95},
      {"scans", {{"localized", 88}, {"odometry", 5}, {"lost", 7}}},
      {"fixes", 1},
      {"losses", nlohmann::json::object()},
      {"search", {{"keyframes", 4}, {"rejected", {{"awaiting <confirmation>", 1}}}}},
      {"lost_periods", {{{"from_s", 3.0}, {"seconds", 0.5}, {"scans", 5}, {"found_again", true}}}},
      {"events", {{{"scan", 7}, {"t_s", 0.7}, {"event", "localized at <here>"}}}},
      {"plan", {{"file", "topdown.png"}}}};
  report["eval"] = {{"localized", {{"translation_m", spread}, {"rotation_deg", spread}}},
                    {"localized_over_0_5_m", 0}};
  report["timings"] = {{"tracking", timing}, {"per_scan", timing}};
  return report;
}

TEST(HtmlReport, ALocalizationRunShowsWhenItWasFoundAndHowWell) {
  const fs::path folder = test::scratch_dir("html_report_localization");
  write_file(folder / "topdown.png", "\x89PNG localized path");
  const std::string html = html_report(localization_report(), folder);
  EXPECT_NE(html.find("featsense localization report: drive.bag"), std::string::npos);
  EXPECT_NE(html.find("after 0.7 s of the input (scan 7), by descriptor, at (1.0, 2.0, 3.0) m"),
            std::string::npos);
  EXPECT_NE(html.find("95.0 %"), std::string::npos);
  EXPECT_NE(html.find("median 1 cm, p95 2 cm, max 3 cm (90 poses)"), std::string::npos);
  EXPECT_NE(html.find("median 30 ms, p95 40 ms, max 50 ms (90 scans)"), std::string::npos);
  EXPECT_NE(html.find("<h3>Lost after the first fix</h3>"), std::string::npos);
  EXPECT_NE(html.find("localized at &lt;here&gt;"), std::string::npos);
  EXPECT_NE(html.find("1 awaiting &lt;confirmation&gt;"), std::string::npos);
  EXPECT_NE(html.find("Plan view with the localized path"), std::string::npos);
  EXPECT_NE(html.find(base64_encode(std::string("\x89PNG localized path"))), std::string::npos);
  // Not a mapping run's page: no pipeline stages, no loops.
  EXPECT_EQ(html.find("Where the time went"), std::string::npos);
  EXPECT_EQ(html.find("<h2>Loop closure</h2>"), std::string::npos);
}

}  // namespace
}  // namespace featsense::viewer_export
