#include "cli_context.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace featsense::app {

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

config::Config CliContext::load_config() const {
  return config::load_config(config_path, overrides);
}

void CliContext::setup_logging() const {
  auto logger = spdlog::stderr_color_mt("featsense");
  logger->set_pattern("%^%l%$: %v");
  logger->set_level(quiet ? spdlog::level::warn : spdlog::level::info);
  spdlog::set_default_logger(logger);
}

}  // namespace featsense::app
