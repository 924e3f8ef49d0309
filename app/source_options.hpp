#pragma once
// The command-line options that say how to read a recording (shared by info, convert, map).

#include <CLI/CLI.hpp>

#include <memory>
#include <optional>
#include <string>

#include "featsense/config/config.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::app {

struct InputOptions {
  std::string input;  ///< file or folder; empty: the built-in example
  std::optional<std::string> meta_path;
  std::optional<std::string> topic;

  /// Adds INPUT (optional when `input_optional`), --meta and --topic to `command`.
  void add_to(CLI::App& command, bool input_optional);
  /// Opens the input with the sensor settings of `config`; the built-in example when no
  /// input was given. Throws slam::InputError.
  std::unique_ptr<slam::ScanSource> open(const config::Config& config) const;
};

}  // namespace featsense::app
