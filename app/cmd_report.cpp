// featsense report OUT: report.html again from an output folder's report.json and pictures
// (after a map written by an older featsense, or to restyle it).

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "commands.hpp"
#include "report_html.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

void run_report(const std::string& folder, const CliContext& context) {
  const fs::path out(folder);
  const fs::path json_file = out / "report.json";
  std::ifstream in(json_file);
  if (!in) throw std::runtime_error(json_file.string() + ": no report.json in " + folder);
  nlohmann::json report;
  try {
    report = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(json_file.string() + ": not JSON (" + e.what() + ")");
  }
  write_report_html(out, report);
  if (!context.quiet) std::printf("%s\n", (out / kReportHtml).string().c_str());
}

}  // namespace

Command register_report(CLI::App& app, const CliContext& context) {
  auto folder = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "report", "Write report.html again from an output folder's report.json and pictures");
  command->add_option("OUT", *folder, "The output folder of featsense map or demo")
      ->required()
      ->check(CLI::ExistingDirectory);
  return {command, [folder, &context] { run_report(*folder, context); }};
}

}  // namespace featsense::app
