#include "velodyne/velodyne_setup.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {
namespace {

std::string read_calibration_file(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(path + ": cannot open the Velodyne calibration (sensor.calibration)");
  std::ostringstream text;
  text << file.rdbuf();
  return text.str();
}

}  // namespace

VelodyneSetup velodyne_setup(
    const uint8_t* first_packet, const SourceOptions& options,
    const std::function<config::SensorModel(const SourceOptions&, const std::string&)>& sensor_for,
    const std::string& origin) {
  VelodyneSetup setup;
  const uint8_t product_id = first_packet[kVelodyneProductIdByte];
  char how[96];
  if (const auto model = velodyne_model_from_product_id(product_id)) {
    setup.model = *model;
    std::snprintf(how, sizeof how, "product id 0x%02X", product_id);
  } else if (const auto preset = velodyne_model_from_preset(options.sensor_preset)) {
    setup.model = *preset;
    std::snprintf(how, sizeof how, "sensor.preset %s", options.sensor_preset.c_str());
  } else {
    char message[256];
    std::snprintf(message, sizeof message,
                  ": the Velodyne packets' product id 0x%02X names no model this reader knows; "
                  "set sensor.preset to vlp16, vlp32c, hdl32, hdl64 or vls128",
                  product_id);
    throw InputError(origin + message);
  }
  if (options.velodyne_calibration) {
    setup.calibration =
        parse_velodyne_calibration(read_calibration_file(*options.velodyne_calibration),
                                   *options.velodyne_calibration, setup.model);
  } else {
    try {
      setup.calibration = builtin_velodyne_calibration(setup.model);
    } catch (const InputError& e) {
      throw InputError(origin + ": " + e.what());
    }
  }
  SourceOptions preset_options = options;
  preset_options.sensor_preset = "auto";  // the model's own preset, whatever was set
  setup.sensor = velodyne_sensor_model(sensor_for(preset_options, velodyne_preset(setup.model)),
                                       setup.calibration);
  setup.settings.cut_angle_rad = options.scan_cut_deg * M_PI / 180.0;
  setup.settings.columns = setup.sensor.columns;
  setup.detail = velodyne_name(setup.model) + " (" + how + "), calibration " +
                 setup.calibration.origin + ", scans cut at " +
                 std::to_string(static_cast<int>(std::lround(options.scan_cut_deg))) + " deg";
  return setup;
}

VelodyneScanAssembler make_velodyne_assembler(const VelodyneSetup& setup) {
  return VelodyneScanAssembler(VelodynePacketDecoder(setup.model, setup.calibration),
                               setup.calibration, setup.settings);
}

std::vector<std::string> velodyne_fields() { return {"x", "y", "z", "intensity", "ring", "time"}; }

}  // namespace featsense::slam
