#pragma once
/// Per-laser corrections of a Velodyne sensor: the layout of the calibration YAML that the
/// ROS drivers use (num_lasers, distance_resolution, lasers: laser_id, rot_correction,
/// vert_correction (rad), dist_correction, vert_offset_correction, horiz_offset_correction
/// (m), ...), or a built-in table of the model's nominal angles.

#include <string>
#include <vector>

#include "velodyne/velodyne_model.hpp"

namespace featsense::slam {

struct VelodyneLaser {
  double vert_rad = 0.0;  ///< elevation above the horizontal
  double rot_rad = 0.0;   ///< subtracted from the block azimuth (clockwise, from +x)
  double dist_correction_m = 0.0;
  double vert_offset_m = 0.0;
  double horiz_offset_m = 0.0;
};

struct VelodyneCalibration {
  std::vector<VelodyneLaser> lasers;  ///< by laser number in the packet
  std::string origin;                 ///< file name or "built-in <model>"
};

/// Parses a calibration YAML. Throws InputError naming `origin` and the laser or key at
/// fault, and where the laser count differs from the model's.
VelodyneCalibration parse_velodyne_calibration(const std::string& yaml_text,
                                               const std::string& origin, VelodyneModel model);

/// The model's nominal table. Throws InputError for the HDL-64E, whose every unit comes
/// with a calibration of its own (a nominal one would misplace points by decimetres).
VelodyneCalibration builtin_velodyne_calibration(VelodyneModel model);

}  // namespace featsense::slam
