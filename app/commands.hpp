#pragma once
// Each subcommand registers itself on the top-level app and returns the work to run once
// the command line is parsed (so that logging is set up and errors are reported in one place).

#include <CLI/CLI.hpp>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_context.hpp"

namespace featsense::app {

/// A command that ran but did not do what was asked (e.g. a sensor never found in a map): its
/// message, and an exit status of its own that scripts can tell from an error (1).
class CommandFailed : public std::runtime_error {
 public:
  CommandFailed(const std::string& message, int exit_code)
      : std::runtime_error(message), exit_code_(exit_code) {}
  int exit_code() const { return exit_code_; }

 private:
  int exit_code_;
};

struct Command {
  CLI::App* parser;
  std::function<void()> run;
};

/// `featsense info INPUT`: what a recording holds.
Command register_info(CLI::App& app, const CliContext& context);
/// `featsense convert INPUT -o DIR`: one file per frame.
Command register_convert(CLI::App& app, const CliContext& context);
/// `featsense simulate --scene NAME|MESH -o DIR`: a simulated recording with ground truth.
Command register_simulate(CLI::App& app, const CliContext& context);
/// `featsense demo [-o OUT] [--scene ...]`: simulate, map, mesh and evaluate a built-in scene.
Command register_demo(CLI::App& app, const CliContext& context);
/// `featsense bench store ...`, added to the `bench` command.
Command register_bench_store(CLI::App& bench, const CliContext& context);
/// `featsense bench features|odometry ...`: the front end's speed, added to `bench`.
std::vector<Command> register_bench_front_end(CLI::App& bench, const CliContext& context);
/// `featsense map INPUT -o OUT --gt TRAJ ...`: the mapping pipeline.
Command register_map(CLI::App& app, const CliContext& context);
/// `featsense bench tsdf|mesh ...`: speed figures as JSON (one command per benchmark).
std::vector<Command> register_bench(CLI::App& app, const CliContext& context);
/// `featsense eval traj|mesh ...`: figures against ground truth (one command per subcommand).
std::vector<Command> register_eval(CLI::App& app, const CliContext& context);
/// `featsense merge A.h5 B.h5 -o C.h5`: two maps of one place as one.
Command register_merge(CLI::App& app, const CliContext& context);
/// `featsense export MESH -o FILE`: a mesh in another format, chosen by the extension.
Command register_export(CLI::App& app, const CliContext& context);
/// `featsense mesh MAP -o MESH`: marching cubes over a stored map.
Command register_mesh(CLI::App& app, const CliContext& context);
/// `featsense report OUT`: report.html from OUT/report.json and the pictures beside it.
Command register_report(CLI::App& app, const CliContext& context);
/// `featsense navmesh MESH -o NAV`: traversability layers for mesh-based navigation.
Command register_navmesh(CLI::App& app, const CliContext& context);
/// `featsense live --sensor ouster|velodyne -o OUT ...`: maps a sensor on the network.
Command register_live(CLI::App& app, const CliContext& context);
/// `featsense replay REC.pcap [--to ADDR] [--rate R] ...`: a recording sent as the sensor did.
Command register_replay(CLI::App& app, const CliContext& context);
/// `featsense localize MAP.h5 INPUT -o OUT`: poses in a saved map, the map read only.
Command register_localize(CLI::App& app, const CliContext& context);
/// `featsense view OUT [--port N]`: the output folder in the browser, until Ctrl+C.
Command register_view(CLI::App& app, const CliContext& context);

}  // namespace featsense::app
