// featsense: LiDAR recordings in, surface maps out. Subcommands are in cmd_*.cpp.

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>

#include "cli_context.hpp"
#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/slam/scan_source.hpp"
#include "malloc_arenas.hpp"
#include "stop_signal.hpp"

namespace {

std::vector<std::string> subcommand_names(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
  return names;
}

/// For "featsense inof": CLI11 would only say that a subcommand is required.
std::string unknown_command_message(const CLI::App& app, const std::string& word) {
  std::string message = "unknown command '" + word + "'";
  const std::string match = featsense::config::closest_match(word, subcommand_names(app));
  if (!match.empty()) message += " (did you mean '" + match + "'?)";
  return message + "; see featsense --help";
}

int fail(const std::string& message, int code) {
  std::fprintf(stderr, "featsense: error: %s\n", message.c_str());
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  featsense::app::limit_malloc_arenas();
  CLI::App app("featsense: LiDAR mapping with a feature-based front end and a TSDF map",
               "featsense");
  app.set_version_flag("--version", "featsense " FEATSENSE_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // global options may also follow the subcommand
  featsense::app::CliContext context;
  context.add_options(app);
  std::vector<featsense::app::Command> commands = {featsense::app::register_info(app, context),
                                                   featsense::app::register_convert(app, context),
                                                   featsense::app::register_simulate(app, context),
                                                   featsense::app::register_map(app, context),
                                                   featsense::app::register_merge(app, context),
                                                   featsense::app::register_demo(app, context),
                                                   featsense::app::register_export(app, context),
                                                   featsense::app::register_navmesh(app, context),
                                                   featsense::app::register_mesh(app, context),
                                                   featsense::app::register_report(app, context),
                                                   featsense::app::register_view(app, context),
                                                   featsense::app::register_replay(app, context),
                                                   featsense::app::register_live(app, context),
                                                   featsense::app::register_localize(app, context)};
  for (auto& command : featsense::app::register_eval(app, context)) commands.push_back(command);
  for (auto& command : featsense::app::register_bench(app, context)) commands.push_back(command);
  commands.push_back(featsense::app::register_bench_store(*app.get_subcommand("bench"), context));
  for (auto& command :
       featsense::app::register_bench_front_end(*app.get_subcommand("bench"), context))
    commands.push_back(command);

  // Global options are parsed wherever they stand; say so in every subcommand's help.
  for (const auto& command : commands) {
    command.parser->footer(
        "Global options (before or after the command): -q,--quiet  -c,--config FILE  "
        "--set KEY=VALUE (repeatable); see featsense --help");
  }
  const std::vector<std::string> names = subcommand_names(app);
  if (argc > 1 && argv[1][0] != '-' &&
      std::find(names.begin(), names.end(), argv[1]) == names.end()) {
    return fail(unknown_command_message(app, argv[1]), 2);
  }

  try {
    app.parse(argc, argv);
    context.setup_logging();
    for (const auto& command : commands) {
      if (command.parser->parsed()) command.run();
    }
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const featsense::config::ConfigError& e) {
    return fail(std::string("config: ") + e.what(), 2);
  } catch (const featsense::app::CommandFailed& e) {
    return fail(e.what(), e.exit_code());
  } catch (const featsense::app::Interrupted& e) {
    return fail(e.what(), 130);
  } catch (const featsense::slam::InputError& e) {
    return fail(e.what(), 1);
  } catch (const std::exception& e) {
    return fail(e.what(), 1);
  }
  return 0;
}
