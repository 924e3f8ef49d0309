#include "featsense/slam/io/sequence_file.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>

#include "featsense/config/config_error.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam::cloud {
namespace {

constexpr const char* kFormat = "featsense-sequence";
constexpr int kVersion = 1;

template <typename T>
T value_of(const YAML::Node& node, const std::string& key, const std::string& origin) {
  if (!node) throw InputError(origin + ": missing key '" + key + "'");
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw InputError(origin + ": key '" + key + "' has the wrong type");
  }
}

SequenceFile parse_document(const std::string& text, const std::string& origin) {
  YAML::Node doc;
  try {
    doc = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(origin + ": invalid YAML: " + e.msg);
  }
  if (!doc.IsMap()) throw InputError(origin + ": expected a mapping");
  static const std::set<std::string> kKeys = {"format", "version", "sensor", "rate_hz", "frames"};
  for (const auto& entry : doc) {
    const std::string key = entry.first.as<std::string>();
    if (!kKeys.count(key)) throw InputError(origin + ": unknown key '" + key + "'");
  }
  if (value_of<std::string>(doc["format"], "format", origin) != kFormat) {
    throw InputError(origin + ": format must be '" + std::string(kFormat) + "'");
  }
  const int version = value_of<int>(doc["version"], "version", origin);
  if (version != kVersion) {
    throw InputError(origin + ": version " + std::to_string(version) +
                     " is not supported (this program reads version " + std::to_string(kVersion) +
                     ")");
  }

  SequenceFile sequence;
  const YAML::Node sensor = doc["sensor"];
  if (!sensor) throw InputError(origin + ": missing key 'sensor'");
  try {
    if (sensor.IsScalar()) {
      sequence.sensor = config::sensor_preset(sensor.as<std::string>());
      sequence.sensor_is_preset = true;
    } else {
      YAML::Emitter out;
      out << sensor;
      sequence.sensor = config::parse_sensor_preset(out.c_str(), origin + " key 'sensor'");
    }
  } catch (const config::ConfigError& e) {
    throw InputError(origin + ": sensor: " + e.what());
  }
  sequence.rate_hz = doc["rate_hz"] ? value_of<double>(doc["rate_hz"], "rate_hz", origin)
                                    : sequence.sensor.rate_hz;
  if (!(sequence.rate_hz > 0.0 && sequence.rate_hz <= 100.0)) {
    throw InputError(origin + ": rate_hz must be in (0, 100]");
  }

  const YAML::Node frames = doc["frames"];
  if (!frames || !frames.IsSequence()) throw InputError(origin + ": 'frames' must be a list");
  for (size_t i = 0; i < frames.size(); ++i) {
    const std::string where = "frames[" + std::to_string(i) + "]";
    const YAML::Node frame = frames[i];
    if (!frame.IsMap()) throw InputError(origin + ": " + where + " must be a mapping");
    SequenceFrame entry;
    entry.file = value_of<std::string>(frame["file"], where + ".file", origin);
    entry.stamp_ns = value_of<int64_t>(frame["stamp_ns"], where + ".stamp_ns", origin);
    if (entry.file.empty() || entry.file.front() == '/' ||
        entry.file.find("..") != std::string::npos) {
      throw InputError(origin + ": " + where + ".file must name a file inside the folder");
    }
    sequence.frames.push_back(std::move(entry));
  }
  return sequence;
}

}  // namespace

SequenceFile parse_sequence_yaml(const std::string& text, const std::string& origin) {
  try {
    return parse_document(text, origin);
  } catch (const YAML::Exception& e) {
    // Odd shapes the checks above do not name (a mapping as a key, ...).
    throw InputError(origin + ": unexpected YAML structure: " + e.msg);
  }
}

std::string format_sequence_yaml(const SequenceFile& sequence) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << kFormat;
  out << YAML::Key << "version" << YAML::Value << kVersion;
  out << YAML::Key << "sensor" << YAML::Value;
  const config::SensorModel& s = sequence.sensor;
  if (sequence.sensor_is_preset) {
    out << s.name;
  } else {
    std::vector<double> elevation_deg, azimuth_deg;
    for (double e : s.elevation_rad) elevation_deg.push_back(e * 180.0 / M_PI);
    for (double a : s.azimuth_offset_rad) azimuth_deg.push_back(a * 180.0 / M_PI);
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << s.name;
    out << YAML::Key << "beams" << YAML::Value << s.beams;
    out << YAML::Key << "columns" << YAML::Value << s.columns;
    out << YAML::Key << "rate_hz" << YAML::Value << s.rate_hz;
    out << YAML::Key << "elevation_deg" << YAML::Value << YAML::Flow << elevation_deg;
    out << YAML::Key << "azimuth_offset_deg" << YAML::Value << YAML::Flow << azimuth_deg;
    out << YAML::Key << "beam_origin_offset_m" << YAML::Value << s.beam_origin_offset_m;
    out << YAML::Key << "min_range_m" << YAML::Value << s.min_range_m;
    out << YAML::Key << "max_range_m" << YAML::Value << s.max_range_m;
    out << YAML::EndMap;
  }
  out << YAML::Key << "rate_hz" << YAML::Value << sequence.rate_hz;
  out << YAML::Key << "frames" << YAML::Value << YAML::BeginSeq;
  for (const SequenceFrame& f : sequence.frames) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "file" << YAML::Value << f.file;
    out << YAML::Key << "stamp_ns" << YAML::Value << f.stamp_ns;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace featsense::slam::cloud
