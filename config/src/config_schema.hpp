#pragma once
// The table of configuration keys: one entry per leaf key, with its parser (type and range
// checks) and its printer. Private to config/.

#include <yaml-cpp/yaml.h>

#include <functional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"

namespace featsense::config::detail {

struct KeySpec {
  std::string path;  ///< "section.key"
  /// Parses `value` into `config`; throws ConfigError with `where` in the message.
  std::function<void(Config& config, const YAML::Node& value, const std::string& where)> parse;
  /// The current value as a YAML node.
  std::function<YAML::Node(const Config& config)> print;
};

/// Every key, in the order of default.yaml.
const std::vector<KeySpec>& key_specs();

/// Checks that hold between keys (e.g. truncation at least one voxel); throws ConfigError.
void validate_relations(const Config& config);

}  // namespace featsense::config::detail
