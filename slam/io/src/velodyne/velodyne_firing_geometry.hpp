#pragma once
/// The grid that `featsense simulate` fires to write a Velodyne's packets: one simulated
/// column per firing sequence, each row a laser with the azimuth that the packet reader will
/// give its returns (velodyne_packet.cpp), so that the packets decode to the simulated points.

#include <cstdint>
#include <string>
#include <vector>

#include "featsense/config/sensor_model.hpp"
#include "velodyne/velodyne_model.hpp"

namespace featsense::slam {

struct VelodyneFiringGeometry {
  VelodyneModel model = VelodyneModel::kHdl32e;
  /// Firing sequences per revolution: the simulated columns. The motor turns at exactly
  /// sensor.rate_hz, so one firing takes 1 / (columns * rate_hz), within 0.2 % of the model's.
  int columns = 0;
  int columns_per_block = 1;  ///< 2 on the VLP-16 (two firing sequences per data block)
  /// Clockwise from +x, of column 0's firing: the reader's default scan cut
  /// (sensor.scan_cut_deg) plus half a column, so that each simulated revolution reads back
  /// as one scan and each firing lies mid-way in its column of the reader's grid.
  double first_azimuth_rad = 0.0;
  std::vector<int> laser_of_row;  ///< laser number (packet slot) of each row
  /// The simulator's sensor: rows are the lasers by elevation, highest first, as the reader
  /// orders them; `columns` columns; no beam origin offset.
  config::SensorModel sensor;

  /// Column `column`'s firing azimuth, clockwise from +x in the packets' 0.01 deg, rounded.
  /// Columns past the revolution's last continue into the next.
  uint16_t azimuth_centideg(int64_t column) const;
};

/// The firing grid of Velodyne preset `preset` (hdl32, vlp32c or vlp16: their built-in laser
/// tables, which the reader uses without a calibration file) turning `rate_hz` times per
/// second (0: the preset's rate). Throws ConfigError for another preset, a model whose
/// packets are not written (HDL-64E, VLS-128) and a rate outside the sensors' 5 to 20 Hz.
VelodyneFiringGeometry velodyne_firing_geometry(const std::string& preset, double rate_hz);

}  // namespace featsense::slam
