#pragma once
// Opening bags in tests: files in a scratch folder, and the bag source with stand-ins for the
// parts of the library that a test of the bag reading does not need.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/config/sensor_model.hpp"
#include "rosbag/rosbag_source.hpp"

namespace featsense::test {

inline std::string write_bag_file(const std::filesystem::path& dir, const std::string& name,
                                  const std::vector<uint8_t>& bytes) {
  const std::filesystem::path path = dir / name;
  std::ofstream file(path, std::ios::binary);
  file.write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  return path.string();
}

/// The sensor lookup of readers.hpp, restated: the named preset, else the fallback.
inline config::SensorModel preset_lookup(const slam::SourceOptions& options,
                                         const std::string& fallback) {
  const std::string name = options.sensor_preset == "auto" ? fallback : options.sensor_preset;
  try {
    return config::sensor_preset(name);
  } catch (const config::ConfigError& e) {
    throw slam::InputError(std::string("sensor.preset: ") + e.what());
  }
}

/// What the stand-ins saw.
struct StandInLog {
  std::vector<slam::PointCloud> organized_clouds;  ///< handed to the organizer
  std::vector<config::SensorModel> organized_for;
  std::optional<std::string> packet_topic;  ///< asked to decode packets of
};

/// Dependencies whose organizer records the cloud and returns an empty scan of the
/// sensor's size, and whose packet decoder factory records the topic and refuses.
inline slam::RosbagDependencies stand_in_dependencies(StandInLog& log) {
  slam::RosbagDependencies dependencies;
  dependencies.organize = [&log](const slam::PointCloud& cloud, const config::SensorModel& sensor) {
    log.organized_clouds.push_back(cloud);
    log.organized_for.push_back(sensor);
    return slam::Scan::allocate(sensor.beams, sensor.columns);
  };
  dependencies.sensor_for = preset_lookup;
  dependencies.ouster_packets = [&log](const slam::BagTopicContext& context,
                                       slam::SourceInfo&) -> std::unique_ptr<slam::BagScanDecoder> {
    log.packet_topic = context.topic.name;
    throw slam::InputError("Ouster packets are decoded elsewhere");
  };
  return dependencies;
}

/// Every scan of a source.
inline std::vector<slam::Scan> read_scans(slam::ScanSource& source) {
  std::vector<slam::Scan> scans;
  while (std::optional<slam::Scan> scan = source.next()) scans.push_back(std::move(*scan));
  return scans;
}

}  // namespace featsense::test
