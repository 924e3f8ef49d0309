#pragma once
/// What a Velodyne stream is read with: the model (from the packets' product id, else the
/// sensor.preset), the calibration (sensor.calibration, else the model's built-in table),
/// the sensor model and the scan settings. Shared by the pcap and the bag readers.

#include <functional>
#include <string>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/open_scan_source.hpp"
#include "velodyne/velodyne_calibration.hpp"
#include "velodyne/velodyne_scan_assembler.hpp"

namespace featsense::slam {

struct VelodyneSetup {
  VelodyneModel model = VelodyneModel::kVlp16;
  VelodyneCalibration calibration;
  config::SensorModel sensor;
  VelodyneScanSettings settings;
  std::string detail;  ///< "VLP-32C (product id 0x28), calibration ..., cut at 180 deg"
};

/// `first_packet`: a packet of the stream, for its product id. `sensor_for` looks up a
/// preset (sensor_for() of readers.hpp). Throws InputError naming `origin` where the model
/// cannot be told or the calibration cannot be read.
VelodyneSetup velodyne_setup(
    const uint8_t* first_packet, const SourceOptions& options,
    const std::function<config::SensorModel(const SourceOptions&, const std::string&)>& sensor_for,
    const std::string& origin);

/// A VelodyneScanAssembler for a setup.
VelodyneScanAssembler make_velodyne_assembler(const VelodyneSetup& setup);

/// The per-point fields of a Velodyne scan, for SourceInfo.
std::vector<std::string> velodyne_fields();

}  // namespace featsense::slam
