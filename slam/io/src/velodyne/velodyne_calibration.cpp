#include "velodyne/velodyne_calibration.hpp"

#include <yaml-cpp/yaml.h>

#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {

VelodyneCalibration parse_velodyne_calibration(const std::string& yaml_text,
                                               const std::string& origin, VelodyneModel model) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw InputError(origin + ": not readable as YAML (" + e.what() + ")");
  }
  const YAML::Node lasers = root["lasers"];
  if (!lasers || !lasers.IsSequence()) {
    throw InputError(origin + ": no 'lasers' list (not a Velodyne calibration)");
  }
  const size_t expected = static_cast<size_t>(velodyne_lasers(model));
  if (lasers.size() != expected) {
    throw InputError(origin + ": lists " + std::to_string(lasers.size()) + " lasers, the " +
                     velodyne_name(model) + " has " + std::to_string(expected));
  }
  VelodyneCalibration calibration;
  calibration.origin = origin;
  calibration.lasers.resize(expected);
  std::vector<bool> seen(expected, false);
  for (size_t i = 0; i < lasers.size(); ++i) {
    const YAML::Node laser = lasers[i];
    try {
      const int id = laser["laser_id"].as<int>();
      if (id < 0 || static_cast<size_t>(id) >= expected || seen[static_cast<size_t>(id)]) {
        throw InputError(origin + ": laser entry " + std::to_string(i) + " has laser_id " +
                         std::to_string(id) + ", outside 0.." + std::to_string(expected - 1) +
                         " or repeated");
      }
      seen[static_cast<size_t>(id)] = true;
      VelodyneLaser& out = calibration.lasers[static_cast<size_t>(id)];
      out.vert_rad = laser["vert_correction"].as<double>();
      out.rot_rad = laser["rot_correction"].as<double>();
      out.dist_correction_m = laser["dist_correction"].as<double>(0.0);
      out.vert_offset_m = laser["vert_offset_correction"].as<double>(0.0);
      out.horiz_offset_m = laser["horiz_offset_correction"].as<double>(0.0);
    } catch (const YAML::Exception& e) {
      throw InputError(origin + ": laser entry " + std::to_string(i) + ": " + e.what() +
                       " (needs laser_id, vert_correction, rot_correction)");
    }
  }
  return calibration;
}

}  // namespace featsense::slam
