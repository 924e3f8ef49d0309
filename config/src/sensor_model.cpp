#include "featsense/config/sensor_model.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <utility>

#include "featsense/config/config_error.hpp"

namespace featsense::config {
namespace embedded {
std::vector<std::pair<std::string, std::string>> sensor_presets();
}  // namespace embedded

namespace {

constexpr double kDegToRad = M_PI / 180.0;

/// "OS-1-128", "os1_128" and "OS1-128" all become "os1128" for lookup.
std::string canonical(const std::string& name) {
  std::string out;
  for (unsigned char c : name) {
    if (std::isalnum(c)) out += static_cast<char>(std::tolower(c));
  }
  return out;
}

template <typename T>
T required(const YAML::Node& doc, const char* key, const std::string& origin) {
  const YAML::Node node = doc[key];
  if (!node) throw ConfigError(origin + ": missing key '" + key + "'");
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw ConfigError(origin + ": key '" + key + "' has the wrong type");
  }
}

std::vector<double> degrees_to_radians(const std::vector<double>& degrees) {
  std::vector<double> out;
  out.reserve(degrees.size());
  for (double d : degrees) out.push_back(d * kDegToRad);
  return out;
}

}  // namespace

double SensorModel::vertical_fov_rad() const {
  if (elevation_rad.empty()) return 0.0;
  const auto [lo, hi] = std::minmax_element(elevation_rad.begin(), elevation_rad.end());
  return *hi - *lo;
}

void SensorModel::validate() const {
  const std::string who = "sensor model '" + name + "': ";
  if (beams < 1 || beams > 1024) throw ConfigError(who + "beams must be 1 .. 1024");
  if (columns < 1 || columns > 100000) throw ConfigError(who + "columns must be 1 .. 100000");
  if (!(rate_hz > 0.0 && rate_hz <= 100.0)) throw ConfigError(who + "rate_hz must be in (0, 100]");
  if (static_cast<int>(elevation_rad.size()) != beams) {
    throw ConfigError(who + "needs one elevation per beam (" + std::to_string(beams) + "), has " +
                      std::to_string(elevation_rad.size()));
  }
  if (static_cast<int>(azimuth_offset_rad.size()) != beams) {
    throw ConfigError(who + "needs one azimuth offset per beam");
  }
  for (size_t i = 0; i < elevation_rad.size(); ++i) {
    if (!std::isfinite(elevation_rad[i]) || std::abs(elevation_rad[i]) > M_PI / 2) {
      throw ConfigError(who + "beam " + std::to_string(i) + " has an impossible elevation");
    }
    if (i > 0 && elevation_rad[i] > elevation_rad[i - 1]) {
      throw ConfigError(who + "beam elevations must be listed from the highest to the lowest");
    }
  }
  if (!(min_range_m >= 0.0 && max_range_m > min_range_m)) {
    throw ConfigError(who + "needs 0 <= min_range_m < max_range_m");
  }
  if (!(beam_origin_offset_m >= 0.0 && beam_origin_offset_m < 1.0)) {
    throw ConfigError(who + "beam_origin_offset_m must be in [0, 1) m");
  }
}

SensorModel parse_sensor_preset(const std::string& yaml_text, const std::string& origin) {
  YAML::Node doc;
  try {
    doc = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(origin + ": invalid YAML: " + e.msg);
  }
  if (!doc.IsMap()) throw ConfigError(origin + ": expected a mapping");
  SensorModel model;
  model.name = required<std::string>(doc, "name", origin);
  model.beams = required<int>(doc, "beams", origin);
  model.columns = required<int>(doc, "columns", origin);
  model.rate_hz = required<double>(doc, "rate_hz", origin);
  model.beam_origin_offset_m = required<double>(doc, "beam_origin_offset_m", origin);
  model.min_range_m = required<double>(doc, "min_range_m", origin);
  model.max_range_m = required<double>(doc, "max_range_m", origin);
  if (doc["elevation_deg"]) {
    model.elevation_rad =
        degrees_to_radians(required<std::vector<double>>(doc, "elevation_deg", origin));
  } else {
    const auto vfov = required<std::vector<double>>(doc, "vfov_deg", origin);
    if (vfov.size() != 2) throw ConfigError(origin + ": vfov_deg must be [highest, lowest]");
    for (int i = 0; i < model.beams; ++i) {
      const double t = model.beams > 1 ? static_cast<double>(i) / (model.beams - 1) : 0.0;
      model.elevation_rad.push_back((vfov[0] + t * (vfov[1] - vfov[0])) * kDegToRad);
    }
  }
  if (doc["azimuth_offset_deg"]) {
    model.azimuth_offset_rad =
        degrees_to_radians(required<std::vector<double>>(doc, "azimuth_offset_deg", origin));
  } else {
    model.azimuth_offset_rad.assign(static_cast<size_t>(std::max(model.beams, 0)), 0.0);
  }
  model.validate();
  return model;
}

std::vector<std::string> sensor_preset_names() {
  std::vector<std::string> names;
  for (const auto& [file, text] : embedded::sensor_presets()) {
    names.push_back(file.substr(0, file.rfind('.')));
  }
  std::sort(names.begin(), names.end());
  return names;
}

SensorModel sensor_preset(const std::string& name) {
  for (const auto& [file, text] : embedded::sensor_presets()) {
    if (canonical(file.substr(0, file.rfind('.'))) == canonical(name)) {
      return parse_sensor_preset(text, "preset " + file);
    }
  }
  std::string message = "unknown sensor preset '" + name + "'";
  const std::string hint = closest_match(name, sensor_preset_names());
  if (!hint.empty()) message += " (did you mean '" + hint + "'?)";
  message += "; presets:";
  for (const auto& preset : sensor_preset_names()) message += " " + preset;
  throw ConfigError(message);
}

}  // namespace featsense::config
