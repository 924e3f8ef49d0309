#pragma once
/// The geometry of a spinning LiDAR: what readers, the simulator and the TSDF need to know
/// about the sensor. Filled from the sensor's own metadata (Ouster JSON) where a recording
/// has some, else from a preset (config/presets/*.yaml).

#include <string>
#include <vector>

namespace featsense::config {

struct SensorModel {
  std::string name;       ///< preset name or product line, e.g. "os1-128"
  int beams = 0;          ///< rows of the range image
  int columns = 0;        ///< columns per revolution
  double rate_hz = 10.0;  ///< revolutions per second
  /// Elevation of each beam above the horizontal plane, radians, row 0 = highest beam.
  std::vector<double> elevation_rad;
  /// Horizontal offset of each beam from its column's azimuth, radians (0 where none).
  std::vector<double> azimuth_offset_rad;
  double beam_origin_offset_m = 0.0;  ///< lidar origin to beam origin (Ouster), metres
  double min_range_m = 0.0;           ///< closer returns are dropped, metres
  double max_range_m = 0.0;           ///< farther returns are dropped, metres

  /// Highest minus lowest beam elevation, radians.
  double vertical_fov_rad() const;
  /// Throws ConfigError naming the problem when the model is inconsistent.
  void validate() const;
};

/// The names of the built-in presets, sorted.
std::vector<std::string> sensor_preset_names();
/// A built-in preset by name (case-insensitive; "OS-1-128" and "os1-128" both work).
/// Throws ConfigError with a did-you-mean when the name is unknown.
SensorModel sensor_preset(const std::string& name);
/// Parses a preset document (the format of config/presets/*.yaml). `origin` names the
/// source in error messages.
SensorModel parse_sensor_preset(const std::string& yaml_text, const std::string& origin);

}  // namespace featsense::config
