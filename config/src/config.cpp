#include "featsense/config/config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "config_schema.hpp"
#include "featsense/config/config_error.hpp"

namespace featsense::config {
namespace {

using detail::key_specs;
using detail::KeySpec;

const KeySpec* find_key(const std::string& path) {
  for (const auto& spec : key_specs()) {
    if (spec.path == path) return &spec;
  }
  return nullptr;
}

std::set<std::string> section_names() {
  std::set<std::string> sections;
  for (const auto& spec : key_specs()) sections.insert(spec.path.substr(0, spec.path.find('.')));
  return sections;
}

[[noreturn]] void unknown_key(const std::string& path, const std::string& where,
                              const std::vector<std::string>& candidates = config_keys()) {
  std::string message = where + ": unknown config key '" + path + "'";
  const std::string hint = closest_match(path, candidates);
  if (!hint.empty()) message += " (did you mean '" + hint + "'?)";
  throw ConfigError(message);
}

std::string location(const std::string& origin, const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  if (mark.is_null()) return origin;
  return origin + ":" + std::to_string(mark.line + 1);
}

void apply_document(Config& config, const YAML::Node& root, const std::string& origin) {
  if (root.IsNull()) return;  // an empty file changes nothing
  if (!root.IsMap()) throw ConfigError(origin + ": expected a mapping of config sections");
  const auto sections = section_names();
  for (const auto& section : root) {
    const std::string section_name = section.first.as<std::string>();
    if (sections.count(section_name) == 0) {
      unknown_key(section_name, location(origin, section.first),
                  std::vector<std::string>(sections.begin(), sections.end()));
    }
    if (section.second.IsNull()) continue;
    if (!section.second.IsMap()) {
      throw ConfigError(location(origin, section.second) + ": section '" + section_name +
                        "' must be a mapping of keys");
    }
    for (const auto& entry : section.second) {
      const std::string path = section_name + "." + entry.first.as<std::string>();
      const KeySpec* spec = find_key(path);
      const std::string line = location(origin, entry.first);
      if (spec == nullptr) unknown_key(path, line);
      spec->parse(config, entry.second, line + ": " + path);
      config.explicit_keys[path] = line;
    }
  }
}

/// Parses `value_text` as YAML into `key`; `where` starts every message, `origin` is
/// recorded as where the key was set.
void apply_value(Config& config, const KeySpec& spec, const std::string& value_text,
                 const std::string& where, const std::string& origin) {
  YAML::Node value;
  try {
    value = YAML::Load(value_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(where + ": cannot parse the value: " + e.msg);
  }
  spec.parse(config, value, where);
  config.explicit_keys[spec.path] = origin;
}

void apply_assignment(Config& config, const std::string& assignment) {
  const std::string where = "--set " + assignment;
  const size_t equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw ConfigError(where + ": expected key=value, e.g. map.voxel_size=0.05");
  }
  const std::string path = assignment.substr(0, equals);
  const KeySpec* spec = find_key(path);
  if (spec == nullptr) unknown_key(path, "--set");
  apply_value(config, *spec, assignment.substr(equals + 1), where, where);
}

void apply_option(Config& config, const Override& option) {
  const KeySpec* spec = find_key(option.key);
  if (spec == nullptr) unknown_key(option.key, option.origin);
  apply_value(config, *spec, option.value, option.origin + ": " + option.key, option.origin);
}

Config build(const std::function<void(Config&)>& apply_file,
             const std::vector<std::string>& overrides, const std::vector<Override>& options) {
  Config config;
  apply_file(config);
  for (const auto& assignment : overrides) apply_assignment(config, assignment);
  for (const auto& option : options) apply_option(config, option);
  detail::validate_relations(config);
  return config;
}

YAML::Node parse_yaml(const std::string& text, const std::string& origin) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(origin + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
}

}  // namespace

std::string to_string(Backend backend) {
  switch (backend) {
    case Backend::kCuda:
      return "cuda";
    case Backend::kCpu:
      return "cpu";
    case Backend::kAuto:
      break;
  }
  return "auto";
}

std::vector<std::string> config_keys() {
  std::vector<std::string> keys;
  for (const auto& spec : key_specs()) keys.push_back(spec.path);
  return keys;
}

std::string value_text(const Config& config, const std::string& key) {
  const KeySpec* spec = find_key(key);
  if (spec == nullptr) unknown_key(key, "value_text");
  const auto scalar_text = [](const YAML::Node& node) {
    double number = 0.0;
    if (!YAML::convert<double>::decode(node, number) || !std::isfinite(number)) {
      return node.Scalar();
    }
    char text[32];
    std::snprintf(text, sizeof(text), "%.15g", number);  // 0.064, not 0.064000000000000001
    return std::string(text);
  };
  const YAML::Node value = spec->print(config);
  if (value.IsNull()) return "null";
  if (!value.IsSequence()) return scalar_text(value);
  std::string text = "[";
  for (size_t i = 0; i < value.size(); ++i) text += (i > 0 ? ", " : "") + scalar_text(value[i]);
  return text + "]";
}

Config load_config_text(const std::string& yaml_text, const std::string& origin,
                        const std::vector<std::string>& overrides,
                        const std::vector<Override>& options) {
  return build(
      [&](Config& config) { apply_document(config, parse_yaml(yaml_text, origin), origin); },
      overrides, options);
}

Config load_config(const std::optional<std::string>& yaml_path,
                   const std::vector<std::string>& overrides,
                   const std::vector<Override>& options) {
  if (!yaml_path) return build([](Config&) {}, overrides, options);
  std::ifstream file(*yaml_path, std::ios::binary);
  if (!file) throw ConfigError(*yaml_path + ": cannot open the config file");
  std::ostringstream text;
  text << file.rdbuf();
  return load_config_text(text.str(), *yaml_path, overrides, options);
}

std::string to_yaml(const Config& config) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  std::string open_section;
  for (const auto& spec : key_specs()) {
    const std::string section = spec.path.substr(0, spec.path.find('.'));
    if (section != open_section) {
      if (!open_section.empty()) out << YAML::EndMap;
      out << YAML::Key << section << YAML::Value << YAML::BeginMap;
      open_section = section;
    }
    out << YAML::Key << spec.path.substr(section.size() + 1) << YAML::Value << spec.print(config);
  }
  if (!open_section.empty()) out << YAML::EndMap;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace featsense::config
