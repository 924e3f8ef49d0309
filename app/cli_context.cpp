#include "cli_context.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>

namespace featsense::app {
namespace {

/// The config's list text "[40, 40, 15]" as the option writes it, "40x40x15".
std::string joined_list(std::string list, char separator) {
  std::string joined;
  for (char c : list) {
    if (c == ',') {
      joined += separator;
    } else if (c != '[' && c != ']' && c != ' ') {
      joined += c;
    }
  }
  return joined;
}

}  // namespace

CLI::Option* add_config_option(CLI::App& command, const ConfigOption& option,
                               std::optional<std::string>& value) {
  std::string shown = config::value_text(config::Config{}, option.key);
  if (option.list_separator != 0) shown = joined_list(shown, option.list_separator);
  return command
      .add_option(option.name, value,
                  std::string(option.help) + " (config " + option.key + ", default " + shown + ")")
      ->type_name(option.type)
      ->take_last();  // as with --set, the last one counts
}

void add_config_override(std::vector<config::Override>& overrides, const ConfigOption& option,
                         const std::optional<std::string>& value) {
  if (!value) return;
  std::string yaml = *value;
  if (option.list_separator != 0) {
    // 40x40x15 -> [40,40,15]; the schema then checks the list like any other.
    std::replace(yaml.begin(), yaml.end(), option.list_separator, ',');
    yaml = "[" + yaml + "]";
  }
  overrides.push_back({option.key, yaml, std::string(option.name) + " " + *value});
}

void CliContext::add_options(CLI::App& app) {
  app.add_flag("-q,--quiet", quiet, "Print only warnings and errors; no progress");
  app.add_option("-c,--config", config_path, "YAML config file (keys as in config/default.yaml)")
      ->check(CLI::ExistingFile);
  app.add_option("--set", overrides,
                 "Override one config key, e.g. --set map.voxel_size=0.05 (repeatable)")
      ->type_name("KEY=VALUE")
      ->take_last()
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

config::Config CliContext::load_config(const std::vector<config::Override>& options) const {
  return config::load_config(config_path, overrides, options);
}

void CliContext::setup_logging() const {
  auto logger = spdlog::stderr_color_mt("featsense");
  logger->set_pattern("%^%l%$: %v");
  logger->set_level(quiet ? spdlog::level::warn : spdlog::level::info);
  spdlog::set_default_logger(logger);
}

}  // namespace featsense::app
