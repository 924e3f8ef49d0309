#pragma once
// Reading one scan file into a Scan: the steps the single-file and folder sources share.

#include <filesystem>
#include <string>
#include <vector>

#include "featsense/slam/io/cloud_files.hpp"

namespace featsense::slam::cloud {

enum class CloudFormat { kPcd, kPly, kKittiBin };

/// The whole file; throws InputError when it cannot be read.
std::string read_file_bytes(const std::filesystem::path& path);

/// The file decoded by its format; throws InputError.
DecodedCloud decode_cloud_file(const std::filesystem::path& path, CloudFormat format);

/// One line for the counts organize() or the organized path produced, and a warning for
/// each count that suggests a wrong sensor model.
std::string describe(const OrganizeStats& stats, std::vector<std::string>* warnings,
                     const std::string& origin);

/// Throws InputError where over a fifth of the points of a recording's first cloud lie outside
/// the beams of `sensor` (a preset that does not fit, given or guessed): mapped, every scan would
/// lose that share. The message names the share and the presets whose beams the points lie on.
void check_sensor_fits(const OrganizeStats& stats, const PointCloud& cloud,
                       const config::SensorModel& sensor, const std::string& origin);

}  // namespace featsense::slam::cloud
