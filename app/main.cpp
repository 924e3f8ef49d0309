// featsense: LiDAR recordings in, surface maps out. Subcommands are in cmd_*.cpp.

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

#include "cli_context.hpp"
#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/slam/scan_source.hpp"

namespace {

/// For "featsense inof": CLI11 says only that the argument was not expected.
std::string subcommand_hint(const CLI::App& app, const std::vector<std::string>& extras) {
  if (extras.empty()) return "";
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
  const std::string match = featsense::config::closest_match(extras.front(), names);
  return match.empty() ? "" : " (did you mean '" + match + "'?)";
}

int fail(const std::string& message, int code) {
  std::fprintf(stderr, "featsense: error: %s\n", message.c_str());
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("featsense: LiDAR mapping with a feature-based front end and a TSDF map",
               "featsense");
  app.set_version_flag("--version", "featsense " FEATSENSE_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // global options may also follow the subcommand
  featsense::app::CliContext context;
  context.add_options(app);
  const std::vector<featsense::app::Command> commands = {
      featsense::app::register_info(app, context), featsense::app::register_convert(app, context)};

  try {
    app.parse(argc, argv);
    context.setup_logging();
    for (const auto& command : commands) {
      if (command.parser->parsed()) command.run();
    }
  } catch (const CLI::ExtrasError& e) {
    return fail(std::string(e.what()) + subcommand_hint(app, app.remaining()), 2);
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
  } catch (const featsense::slam::InputError& e) {
    return fail(e.what(), 1);
  } catch (const std::exception& e) {
    return fail(e.what(), 1);
  }
  return 0;
}
