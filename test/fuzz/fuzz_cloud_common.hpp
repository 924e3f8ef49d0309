#pragma once
// What the PCD and PLY fuzz targets share: decoded bytes go all the way to a Scan, and the
// Scan must keep the promises of scan.hpp whatever the input.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "featsense/slam/io/cloud_files.hpp"

namespace featsense::fuzz {

/// Fails loudly (the fuzzer records the input) when `condition` does not hold.
inline void require(bool condition, const char* what) {
  if (condition) return;
  std::fprintf(stderr, "broken promise: %s\n", what);
  std::abort();
}

/// The decoded cloud as a Scan through the reader's own path: the sensor it would choose,
/// else a fixed preset, so that organize() sees every input that decodes.
inline void organize_decoded(const slam::DecodedCloud& decoded, const std::string& origin) {
  static const config::SensorModel fallback = config::sensor_preset("os1-64");
  config::SensorModel sensor;
  try {
    sensor = slam::choose_sensor(decoded, slam::SourceOptions{}, origin);
  } catch (const slam::InputError&) {
    sensor = fallback;
  }
  // Few columns keep each run fast (every cell is checked below); organize() does the same
  // work per point whatever the number of columns.
  if (!decoded.organized()) sensor.columns = std::min(sensor.columns, 64);
  std::vector<std::string> warnings;
  slam::OrganizeStats stats;
  slam::Scan scan;
  try {
    scan = slam::cloud_to_scan(decoded, sensor, origin, &stats, &warnings);
  } catch (const slam::InputError&) {
    return;  // an organized cloud whose height does not fit the sensor
  }
  const size_t n = scan.size();
  require(scan.xyz.size() == n && scan.range_m.size() == n && scan.valid.size() == n &&
              scan.time_offset_s.size() == n,
          "every per-cell array has rows x cols entries");
  require(stats.input_points == decoded.cloud.size(), "every point counted");
  for (size_t i = 0; i < n; ++i) {
    require(std::isfinite(scan.time_offset_s[i]), "finite time offsets");
    if (!scan.valid[i]) continue;
    require(scan.xyz[i].allFinite() && !scan.xyz[i].isZero(0.0f), "valid cells hold data");
    require(std::isfinite(scan.range_m[i]) && scan.range_m[i] > 0.0f, "valid cells have a range");
  }
  for (const slam::ScanChannel& c : scan.channels) {
    require(c.values.size() == n, "channels have rows x cols values");
  }
}

}  // namespace featsense::fuzz
