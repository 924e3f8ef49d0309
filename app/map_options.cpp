#include "map_options.hpp"

#include <cmath>
#include <sstream>
#include <vector>

#include "featsense/config/config_error.hpp"

namespace featsense::app {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// --start / --end: a frame index ("120") or seconds after the first scan ("12.5s").
void parse_range_end(const std::string& text, const char* option, std::optional<uint64_t>& frame,
                     std::optional<double>& seconds) {
  std::istringstream in(text);
  double value = 0.0;
  if (!(in >> value) || value < 0.0) {
    throw config::ConfigError(std::string(option) + ": expected a frame index or seconds like " +
                              "12.5s, got '" + text + "'");
  }
  std::string unit;
  in >> unit;
  if (unit == "s") {
    seconds = value;
  } else if (unit.empty() && value == static_cast<double>(static_cast<uint64_t>(value))) {
    frame = static_cast<uint64_t>(value);
  } else {
    throw config::ConfigError(std::string(option) + ": expected a frame index or seconds like " +
                              "12.5s, got '" + text + "'");
  }
}

}  // namespace

mapping::FrameRange frame_range(const MapOptions& options) {
  mapping::FrameRange range;
  if (options.start) parse_range_end(*options.start, "--start", range.first_frame, range.first_s);
  if (options.end) parse_range_end(*options.end, "--end", range.last_frame, range.last_s);
  return range;
}

Eigen::Isometry3d parse_initial_pose(const std::string& text) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      size_t used = 0;
      values.push_back(std::stod(item, &used));
      if (used != item.size() || !std::isfinite(values.back())) values.clear();
    } catch (const std::exception&) {
      values.clear();
      break;
    }
    if (values.empty()) break;
  }
  if (values.size() != 4) {
    throw config::ConfigError("--initial-pose: expected x,y,z,yaw_deg (metres, degrees), got '" +
                              text + "'");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(values[0], values[1], values[2]);
  T.linear() =
      Eigen::AngleAxisd(values[3] * kPi / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

}  // namespace featsense::app
