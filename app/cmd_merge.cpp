// featsense merge A.h5 B.h5 -o C.h5: two maps of the same place, made apart, as one. B is
// placed in A by the relocalization that places a recording (its keyframes, in order,
// against A's), the sessions of both are linked in one pose graph, and every session is mapped
// again from its input with the corrected poses: a TSDF cannot be moved without resampling it,
// the inputs can be read again.

#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/mapping/merge_maps.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "json_output.hpp"
#include "map_report.hpp"
#include "progress.hpp"
#include "session_links_report.hpp"
#include "stop_signal.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

struct MergeOptions {
  std::string first;
  std::string second;
  std::string output;
  bool overwrite = false;
  std::optional<std::string> backend;
};

void run_merge(const MergeOptions& options, const CliContext& context) {
  std::vector<config::Override> overrides;
  add_config_override(overrides, kBackendOption, options.backend);
  config::Config config = context.load_config(overrides);
  const fs::path output(options.output);
  if (output.extension() != ".h5")
    throw config::ConfigError("merge -o: the merged map is an .h5 file, got " + options.output);
  if (fs::exists(output) && !options.overwrite)
    throw std::runtime_error(options.output + " exists; pass --overwrite to replace it");
  mapping::MergeResult merged;
  {
    const StopSignal stop_signal;
    merged = mapping::merge_maps(options.first, options.second, output, config,
                                 terminal_events(stop_signal.token(), context.quiet));
  }
  const fs::path report_path = fs::path(output).replace_extension(".report.json");
  nlohmann::json report = {
      {"first", options.first}, {"second", options.second}, {"output", options.output}};
  report["relocalization"] = {{"keyframes", merged.tried.keyframes},
                              {"candidates", merged.tried.candidates},
                              {"verified", merged.tried.verified},
                              {"rejected", merged.tried.rejected}};
  report["placed"] = merged.placement.has_value();
  if (!merged.placement) {
    report["why"] = merged.why;
    write_json(report, report_path.string());
    throw std::runtime_error(merged.why);
  }
  report["fitness_m"] = merged.placement->fitness_m;
  report["agreeing"] = merged.placement->agreeing;
  report["links"] = session_links_json(merged.links);
  report["reintegration"] = reintegration_json(merged.reintegration);
  // Each session's poses in the merged map, beside it: C.session0.tum, ...
  for (size_t k = 0; k < merged.sessions.size(); ++k) {
    slam::write_tum(
        merged.sessions[k].poses,
        fs::path(output).replace_extension(".session" + std::to_string(k) + ".tum").string());
  }
  report["sessions"] = sessions_json(output);
  write_json(report, report_path.string());
  if (!context.quiet) {
    std::printf("%s + %s -> %s (%zu sessions, %zu links between them)\n", options.first.c_str(),
                options.second.c_str(), options.output.c_str(), merged.sessions.size(),
                merged.links.linked.links.size());
  }
}

}  // namespace

Command register_merge(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<MergeOptions>();
  CLI::App* command = app.add_subcommand(
      "merge",
      "Join two maps of the same place made apart: B is placed in A by its keyframes, the "
      "sessions are linked, and every session is mapped again from its input");
  command->add_option("A", options->first, "The map whose frame the merged map keeps (.h5)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("B", options->second, "The map placed into it (.h5)")
      ->required()
      ->check(CLI::ExistingFile);
  command
      ->add_option("-o,--output", options->output, "The merged map (.h5); C.report.json beside it")
      ->required();
  command->add_flag("--overwrite", options->overwrite, "Replace the output if it exists");
  add_config_option(*command, kBackendOption, options->backend);
  return {command, [options, &context] { run_merge(*options, context); }};
}

}  // namespace featsense::app
