#pragma once
// What every subcommand shares: the global options (--quiet, --config, --set) and the
// configuration they produce.

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"

namespace featsense::app {

/// A command's option that stands for one config key, e.g. --backend for map.backend. Its
/// value goes through the config's schema as `--set KEY=VALUE` would (one parser, one check,
/// messages naming the option and the key), after the --set ones.
struct ConfigOption {
  const char* name;  ///< "--backend"
  const char* key;   ///< "map.backend"
  const char* type;  ///< the value's form in the help: "NAME", "METRES", "XxYxZ"
  const char* help;  ///< what the option is; the help adds the key and its default
  /// Items of a list value are joined by this, e.g. 'x' for --map 40x40x15; 0: a single value.
  char list_separator = 0;
};

inline constexpr ConfigOption kBackendOption{"--backend", "map.backend", "NAME",
                                             "TSDF backend: auto, cuda or cpu"};
inline constexpr ConfigOption kVoxelOption{"--voxel", "map.voxel_size", "METRES",
                                           "Voxel size, metres"};
inline constexpr ConfigOption kTruncationOption{"--truncation", "map.truncation", "METRES",
                                                "Truncation distance tau, metres"};
inline constexpr ConfigOption kMapSizeOption{"--map", "map.size", "XxYxZ", "Local map size, metres",
                                             'x'};

/// Adds `option` to `command`; the text given is kept in `value` (unset when not given; the
/// last one when given more than once).
CLI::Option* add_config_option(CLI::App& command, const ConfigOption& option,
                               std::optional<std::string>& value);

/// `value` of `option` as a config override (added to `overrides` when given).
void add_config_override(std::vector<config::Override>& overrides, const ConfigOption& option,
                         const std::optional<std::string>& value);

struct CliContext {
  bool quiet = false;
  std::optional<std::string> config_path;
  std::vector<std::string> overrides;  ///< --set key=value, in order

  /// Adds --quiet, --config and --set to `app` (the top level; subcommands fall through).
  void add_options(CLI::App& app);
  /// The configuration of this run: defaults, --config, --set, then `options` (the values of
  /// a command's ConfigOptions). Throws ConfigError.
  config::Config load_config(const std::vector<config::Override>& options = {}) const;
  /// Log level and sinks for this run (stderr; warnings and errors only with --quiet).
  void setup_logging() const;
};

}  // namespace featsense::app
