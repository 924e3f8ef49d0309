#pragma once
// What every subcommand shares: the global options (--quiet, --config, --set) and the
// configuration they produce.

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"

namespace featsense::app {

struct CliContext {
  bool quiet = false;
  std::optional<std::string> config_path;
  std::vector<std::string> overrides;  ///< --set key=value, in order

  /// Adds --quiet, --config and --set to `app` (the top level; subcommands fall through).
  void add_options(CLI::App& app);
  /// The configuration of this run: defaults, --config, then --set. Throws ConfigError.
  config::Config load_config() const;
  /// Log level and sinks for this run (stderr; warnings and errors only with --quiet).
  void setup_logging() const;
};

}  // namespace featsense::app
