#include "velodyne/velodyne_firing_geometry.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "featsense/config/config.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/pcap_recorders.hpp"
#include "velodyne/velodyne_calibration.hpp"
#include "velodyne/velodyne_firing.hpp"
#include "velodyne/velodyne_scan_assembler.hpp"

namespace featsense::slam {
namespace {

constexpr double kMinRateHz = 5.0;  // 300 rpm, the slowest motor speed of all three models
constexpr double kMaxRateHz = 20.0;
constexpr double kCentidegPerRad = 18000.0 / M_PI;

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

VelodyneModel writable_model(const std::string& preset) {
  const std::optional<VelodyneModel> model = velodyne_model_from_preset(lowercase(preset));
  if (!model) {
    throw config::ConfigError("'" + preset +
                              "' is no Velodyne sensor: Velodyne packets are written for the "
                              "presets hdl32, vlp32c and vlp16");
  }
  if (*model == VelodyneModel::kHdl64e || *model == VelodyneModel::kVls128) {
    throw config::ConfigError("writing " + velodyne_name(*model) +
                              " packets is not supported (presets hdl32, vlp32c and vlp16)");
  }
  return *model;
}

/// The reader's rows (velodyne_scan_assembler.cpp): lasers by elevation, highest first, in
/// packet order where two are level.
std::vector<int> lasers_highest_first(const VelodyneCalibration& calibration) {
  std::vector<int> order(calibration.lasers.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return calibration.lasers[static_cast<size_t>(a)].vert_rad >
           calibration.lasers[static_cast<size_t>(b)].vert_rad;
  });
  return order;
}

}  // namespace

uint16_t VelodyneFiringGeometry::azimuth_centideg(int64_t column) const {
  const int64_t turn_column = column % columns;
  const double azimuth_rad =
      first_azimuth_rad + 2.0 * M_PI * static_cast<double>(turn_column) / columns;
  const int64_t centideg = std::llround(azimuth_rad * kCentidegPerRad) % 36000;
  return static_cast<uint16_t>(centideg < 0 ? centideg + 36000 : centideg);
}

VelodyneFiringGeometry velodyne_firing_geometry(const std::string& preset, double rate_hz) {
  VelodyneFiringGeometry g;
  g.model = writable_model(preset);
  const config::SensorModel preset_model = config::sensor_preset(velodyne_preset(g.model));
  const double rate = rate_hz > 0.0 ? rate_hz : preset_model.rate_hz;
  if (!(rate >= kMinRateHz && rate <= kMaxRateHz)) {
    char message[160];
    std::snprintf(message, sizeof message, "the %s turns 5 to 20 times per second, not %g",
                  velodyne_name(g.model).c_str(), rate);
    throw config::ConfigError(message);
  }
  // The built-in table is what the reader decodes with when no calibration file is given.
  // A laser's distance or position offsets would move its returns off the simulated beam,
  // which starts at the lidar origin; refused rather than written wrong.
  const VelodyneCalibration calibration = builtin_velodyne_calibration(g.model);
  for (const VelodyneLaser& laser : calibration.lasers) {
    if (laser.dist_correction_m != 0.0 || laser.vert_offset_m != 0.0 ||
        laser.horiz_offset_m != 0.0) {
      throw config::ConfigError("the " + velodyne_name(g.model) +
                                " laser table has distance or position offsets, which the "
                                "simulated beams cannot follow");
    }
  }

  // One column per firing sequence. The VLP-16's block holds two, and a whole number of
  // blocks per revolution keeps a block from holding the end of one scan and the start of
  // the next (the reader looks for the scan cut once per block).
  g.columns_per_block = g.model == VelodyneModel::kVlp16 ? 2 : 1;
  const double block_us =
      velodyne_firing(g.model, 1, 0, false).time_us - velodyne_firing(g.model, 0, 0, false).time_us;
  g.columns = g.columns_per_block * static_cast<int>(std::lround(1e6 / (rate * block_us)));
  const double step_rad = 2.0 * M_PI / g.columns;
  g.first_azimuth_rad = config::SensorConfig{}.scan_cut_deg * M_PI / 180.0 + 0.5 * step_rad;

  g.sensor = velodyne_sensor_model(preset_model, calibration);
  g.sensor.columns = g.columns;
  g.sensor.rate_hz = rate;
  g.sensor.beam_origin_offset_m = 0.0;
  g.laser_of_row = lasers_highest_first(calibration);
  // The reader gives a return of laser l in a block of azimuth A (clockwise from +x) the
  // azimuth A + T f - rot_l: T the change of azimuth to the next block (columns_per_block
  // steps), f the laser's azimuth fraction (velodyne_firing), rot_l its rot_correction.
  // Column c fires at A_c = first + c step, so laser l looks along A_c + step (cpb f) - rot_l
  // clockwise; the simulator's rows turn anticlockwise (-2 pi c / columns + offset).
  for (size_t row = 0; row < g.laser_of_row.size(); ++row) {
    const size_t laser = static_cast<size_t>(g.laser_of_row[row]);
    const double fraction =
        g.columns_per_block * velodyne_firing(g.model, 0, laser, false).azimuth_fraction;
    g.sensor.azimuth_offset_rad[row] =
        calibration.lasers[laser].rot_rad - g.first_azimuth_rad - fraction * step_rad;
  }
  g.sensor.validate();
  return g;
}

config::SensorModel velodyne_firing_sensor(const std::string& preset, double rate_hz) {
  return velodyne_firing_geometry(preset, rate_hz).sensor;
}

}  // namespace featsense::slam
