#include "cloud/cloud_file_io.hpp"

#include <cmath>
#include <fstream>
#include <system_error>

#include "cloud/sensor_guess.hpp"

namespace featsense::slam::cloud {

std::string read_file_bytes(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(path.string() + ": not a readable file");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path.string() + ": cannot open (permission denied?)");
  std::string bytes;
  // Read in blocks rather than trusting the size the folder reports (it may change).
  constexpr size_t kBlock = size_t{1} << 20;
  while (file) {
    const size_t have = bytes.size();
    bytes.resize(have + kBlock);
    file.read(bytes.data() + have, static_cast<std::streamsize>(kBlock));
    bytes.resize(have + static_cast<size_t>(file.gcount()));
  }
  if (file.bad()) throw InputError(path.string() + ": read error");
  return bytes;
}

DecodedCloud decode_cloud_file(const std::filesystem::path& path, CloudFormat format) {
  const std::string bytes = read_file_bytes(path);
  const std::string origin = path.string();
  if (bytes.empty()) throw InputError(origin + ": empty file");
  switch (format) {
    case CloudFormat::kPcd:
      return decode_pcd(bytes, origin);
    case CloudFormat::kPly:
      return decode_ply(bytes, origin);
    case CloudFormat::kKittiBin:
      return decode_kitti_bin(bytes, origin);
  }
  throw InputError(origin + ": unknown format");
}

std::string describe(const OrganizeStats& stats, std::vector<std::string>* warnings,
                     const std::string& origin) {
  if (warnings && stats.dropped_outside > 0) {
    warnings->push_back(origin + ": " + std::to_string(stats.dropped_outside) +
                        " points outside the sensor's beams dropped (wrong sensor.preset?)");
  }
  // Some points share a cell where the sensor's columns and the cloud's azimuths do not line
  // up exactly (2 % in the HDL-32 recordings) or a driver repeats points at packet borders
  // (14 % in the VLP-16 one); many more mean the sensor model does not fit.
  if (warnings && stats.dropped_collisions * 4 > stats.input_points) {
    warnings->push_back(origin + ": " + std::to_string(stats.dropped_collisions) + " of " +
                        std::to_string(stats.input_points) +
                        " points shared a cell with a nearer one (too few columns?)");
  }
  return std::to_string(stats.input_points) + " points, " + std::to_string(stats.dropped_invalid) +
         " empty (zero or NaN), " + std::to_string(stats.dropped_outside) + " outside the beams, " +
         std::to_string(stats.dropped_collisions) + " in occupied cells";
}

void check_sensor_fits(const OrganizeStats& stats, const PointCloud& cloud,
                       const config::SensorModel& sensor, const std::string& origin) {
  const size_t returns = stats.input_points - stats.dropped_invalid;
  // A model that fits loses next to nothing above its highest or below its lowest beam (the
  // half beam spacing beyond them is kept); a fifth of every scan is never a fit.
  if (returns == 0 || 5 * stats.dropped_outside <= returns) return;
  const std::vector<std::string> fitting = presets_fitting_elevations(cloud);
  std::string presets;
  for (const std::string& name : fitting) presets += (presets.empty() ? "" : ", ") + name;
  const long percent = std::lround(100.0 * static_cast<double>(stats.dropped_outside) /
                                   static_cast<double>(returns));
  throw InputError(origin + ": " + std::to_string(percent) + " % of the points (" +
                   std::to_string(stats.dropped_outside) + " of " + std::to_string(returns) +
                   ") lie outside the beams of sensor " + sensor.name + "; " +
                   (fitting.empty() ? std::string("they lie on no preset's beams either: set "
                                                  "sensor.preset to the sensor that recorded them")
                                    : "presets whose beams they lie on: " + presets +
                                          " (--set sensor.preset=NAME)"));
}

}  // namespace featsense::slam::cloud
