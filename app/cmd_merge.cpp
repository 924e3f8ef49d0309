// featsense merge A.h5 B.h5 -o C.h5: two maps of the same place, made apart, as one. B is
// placed in A by the relocalization that places a recording (its keyframes, in order,
// against A's), the sessions of both are linked in one pose graph, and every session is mapped
// again from its input with the corrected poses: a TSDF cannot be moved without resampling it,
// the inputs can be read again.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/slam/loops/relocalizer.hpp"
#include "featsense/slam/loops/session_links.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "json_output.hpp"
#include "map_continue.hpp"
#include "map_sessions.hpp"
#include "map_store.hpp"
#include "saved_map.hpp"
#include "session_links_report.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;
using slam::loops::MapKeyframe;

struct MergeOptions {
  std::string first;
  std::string second;
  std::string output;
  bool overwrite = false;
  std::optional<std::string> backend;
};

SavedMap read_map_to_merge(const std::string& path, const config::Config& config) {
  SavedMap saved = read_saved_map(path);
  if (saved.keyframes.empty()) {
    throw std::runtime_error(path +
                             " keeps no keyframes (made with given poses, with loop closure off or "
                             "by an older featsense): maps are merged by their keyframes");
  }
  const std::string why = why_sessions_cannot_be_read(saved, config);
  if (!why.empty()) {
    throw std::runtime_error("merge maps every session again from its input, and in " + path + " " +
                             why);
  }
  return saved;
}

void run_merge(const MergeOptions& options, const CliContext& context) {
  std::vector<config::Override> overrides;
  add_config_override(overrides, kBackendOption, options.backend);
  config::Config config = context.load_config(overrides);
  const fs::path output(options.output);
  if (output.extension() != ".h5")
    throw config::ConfigError("merge -o: the merged map is an .h5 file, got " + options.output);
  if (fs::exists(output) && !options.overwrite)
    throw std::runtime_error(options.output + " exists; pass --overwrite to replace it");
  const SavedMap first = read_map_to_merge(options.first, config);
  const SavedMap second = read_map_to_merge(options.second, config);
  adopt_map_geometry(first.metadata, options.first, config);

  // B's keyframes, in order, against A's: the first that is confirmed places B.
  slam::loops::RelocalizeSettings settings;
  settings.loop = slam::loops::from_config(config);
  settings.confirmations = static_cast<size_t>(config.relocalize.confirmations);
  slam::loops::Relocalizer relocalizer(first.keyframes, settings);
  for (const MapKeyframe& keyframe : second.keyframes) {
    if (relocalizer.add_keyframe(keyframe.stamp_ns, keyframe.T_map_sensor, keyframe.travelled_m,
                                 keyframe.cloud.points()))
      break;
  }
  const fs::path report_path = fs::path(output).replace_extension(".report.json");
  nlohmann::json report = {
      {"first", options.first}, {"second", options.second}, {"output", options.output}};
  const slam::loops::RelocalizationCounts& counts = relocalizer.counts();
  report["relocalization"] = {{"keyframes", counts.keyframes},
                              {"candidates", counts.candidates},
                              {"verified", counts.verified},
                              {"rejected", counts.rejected}};
  if (!relocalizer.placement()) {
    std::ostringstream why;
    why << options.second << " could not be placed in " << options.first << ": none of its "
        << second.keyframes.size() << " keyframes matched the " << first.keyframes.size() << " of "
        << options.first << " (" << counts.candidates << " candidates, " << counts.verified
        << " verified); the maps may show different places. Nothing written.";
    report["placed"] = false;
    report["why"] = why.str();
    write_json(report, report_path.string());
    throw std::runtime_error(why.str());
  }
  const slam::loops::Relocalization& placement = *relocalizer.placement();
  report["placed"] = true;
  report["fitness_m"] = placement.fitness_m;
  report["agreeing"] = placement.agreeing;

  // Both maps' sessions in one graph, B's numbered after A's and placed by the match.
  uint32_t offset = 0;
  for (const SavedSession& s : first.sessions) offset = std::max(offset, s.session.id + 1);
  std::vector<MapKeyframe> keyframes = first.keyframes;
  const size_t first_second = keyframes.size();
  for (MapKeyframe keyframe : second.keyframes) {
    keyframe.session += offset;
    keyframe.T_map_sensor = placement.T_map_session * keyframe.T_map_sensor;
    keyframes.push_back(std::move(keyframe));
  }
  slam::loops::SessionLinkSettings link_settings;
  link_settings.loop = settings.loop;
  const slam::loops::SessionLinkResult linked =
      slam::loops::link_sessions(keyframes, link_settings, std::nullopt);
  spdlog::info(
      "{} placed in {} ({} keyframes agreeing, fitness {:.1f} mm); {} links between "
      "the sessions",
      options.second, options.first, placement.agreeing, 1000.0 * placement.fitness_m,
      linked.links.size());
  report["links"] = session_links_json(linked, keyframes);

  std::vector<SessionRemap> sessions =
      session_remaps(first, keyframes, 0, 0, Eigen::Isometry3d::Identity(), linked.poses,
                     "; merged with " + options.second);
  for (SessionRemap& remap :
       session_remaps(second, keyframes, first_second, offset, placement.T_map_session,
                      linked.poses, "; merged into " + options.first + " (relocalized)"))
    sessions.push_back(std::move(remap));
  PipelineSettings replay;
  replay.flush_interval_s = config.map.flush_interval_s;
  replay.quiet = context.quiet;
  replay.drop_mixed_pixels = config.sensor.drop_mixed_pixels;
  const fs::path partial = fs::path(options.output + ".partial");
  build_then_replace(partial, output, [&] {
    remap_sessions(sessions, partial, replay, config, first.metadata.sensor);
  });
  // Each session's poses in the merged map, beside it: C.session0.tum, ...
  for (size_t k = 0; k < sessions.size(); ++k) {
    slam::write_tum(
        sessions[k].poses,
        fs::path(output).replace_extension(".session" + std::to_string(k) + ".tum").string());
  }
  report["sessions"] = sessions_json(output);
  write_json(report, report_path.string());
  if (!context.quiet) {
    std::printf("%s + %s -> %s (%zu sessions, %zu links between them)\n", options.first.c_str(),
                options.second.c_str(), options.output.c_str(), sessions.size(),
                linked.links.size());
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
