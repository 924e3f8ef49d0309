// sensor_for(): kept apart from open_scan_source() so that code using one reader links
// without every other format's reader.

#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/readers.hpp"

namespace featsense::slam {

config::SensorModel sensor_for(const SourceOptions& options, const std::string& fallback_preset) {
  const std::string name =
      options.sensor_preset == "auto" ? fallback_preset : options.sensor_preset;
  try {
    return config::sensor_preset(name);
  } catch (const config::ConfigError& e) {
    throw InputError(std::string("sensor.preset: ") + e.what());
  }
}

}  // namespace featsense::slam
