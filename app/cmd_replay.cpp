// featsense replay: a recorded pcap's UDP payloads sent to a host as the sensor sent them, for
// dry runs of `featsense live` without the sensor.

#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "featsense/slam/io/pcap_replay.hpp"
#include "json_output.hpp"
#include "progress.hpp"
#include "stop_signal.hpp"

namespace featsense::app {
namespace {

struct ReplayOptions {
  std::string input;
  slam::ReplaySettings settings;
  std::vector<std::string> port_maps;  ///< FROM:TO
  std::optional<std::string> json_path;
};

/// "7502:17502" as (7502, 17502); throws CLI::ValidationError otherwise.
std::pair<int, int> parse_port_map(const std::string& text) {
  const size_t colon = text.find(':');
  try {
    if (colon == std::string::npos) throw std::invalid_argument(text);
    size_t used_from = 0;
    size_t used_to = 0;
    const int from = std::stoi(text.substr(0, colon), &used_from);
    const int to = std::stoi(text.substr(colon + 1), &used_to);
    if (used_from != colon || used_to != text.size() - colon - 1) throw std::invalid_argument(text);
    return {from, to};
  } catch (const std::logic_error&) {
    throw CLI::ValidationError("--port", "'" + text + "' is not FROM:TO (e.g. 7502:17502)");
  }
}

void run_replay(ReplayOptions& options, const CliContext& context) {
  for (const std::string& map : options.port_maps) {
    const auto [from, to] = parse_port_map(map);
    options.settings.ports[from] = to;
  }
  const StopSignal stop_signal("ending the replay");
  options.settings.stop_requested = [&stop_signal] { return stop_signal.requested(); };
  Progress progress("datagrams sent", std::nullopt, context.quiet);
  options.settings.progress = [&progress](size_t sent) { progress.update(sent); };
  const slam::ReplayResult result = slam::replay_pcap(options.input, options.settings);
  progress.finish();
  if (!context.quiet) {
    std::printf(
        "replayed %s to %s: %zu datagrams (%zu bytes) in %.1f s over %zu pass(es); %zu dropped "
        "on purpose, %zu failed to send\n",
        options.input.c_str(), options.settings.host.c_str(), result.sent, result.bytes,
        result.seconds, result.passes, result.dropped, result.failed);
  }
  if (options.json_path) {
    nlohmann::json ports = nlohmann::json::object();
    for (const auto& [from, to] : options.settings.ports) ports[std::to_string(from)] = to;
    write_json({{"input", options.input},
                {"host", options.settings.host},
                {"rate", options.settings.rate},
                {"loop", options.settings.loop},
                {"drop_fraction", options.settings.drop_fraction},
                {"seed", options.settings.seed},
                {"ports", ports},
                {"sent", result.sent},
                {"bytes", result.bytes},
                {"dropped", result.dropped},
                {"failed", result.failed},
                {"passes", result.passes},
                {"seconds", result.seconds},
                {"recording_seconds", result.recording_seconds},
                {"stopped", stop_signal.requested()}},
               *options.json_path);
  }
  if (stop_signal.requested()) throw Interrupted("replay stopped");
}

}  // namespace

Command register_replay(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<ReplayOptions>();
  CLI::App* command = app.add_subcommand(
      "replay",
      "Send a pcap's UDP payloads to a host on their recorded ports with their recorded timing, "
      "as the sensor sent them: a dry run for `featsense live`");
  command->add_option("INPUT", options->input, "Recording (.pcap) of an Ouster or Velodyne")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--to", options->settings.host, "IPv4 address to send to")
      ->capture_default_str();
  command->add_option("--rate", options->settings.rate, "Speed against the recording (2: twice)")
      ->check(CLI::Range(1e-3, 1000.0))
      ->capture_default_str();
  command->add_flag("--loop", options->settings.loop,
                    "Start over at the end, until Ctrl+C (the packets keep their timestamps: "
                    "the sensor's clock goes back at each start)");
  command
      ->add_option("--drop", options->settings.drop_fraction,
                   "Drop this share of the datagrams at random, to try a lossy network")
      ->check(CLI::Range(0.0, 0.999))
      ->capture_default_str();
  command->add_option("--seed", options->settings.seed, "Seed of --drop")->capture_default_str();
  command->add_option("--port", options->port_maps,
                      "FROM:TO: send what was recorded on port FROM to port TO (repeatable)");
  command->add_option("--json", options->json_path, "Write what was sent as JSON to this file");
  return {command, [options, &context] { run_replay(*options, context); }};
}

}  // namespace featsense::app
