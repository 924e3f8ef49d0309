// Clouds that carry no sensor metadata (KITTI .bin: x y z intensity) are told by the
// elevations their points lie on: an OS1-128, a VLP-16 or an HDL-32E simulated and written as
// .bin comes back as that sensor, every point in the cell it was measured in (the Ouster's
// beam origin offset included, which at a metre puts a top-beam point a whole beam lower as seen
// from the lidar origin).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/readers.hpp"
#include "featsense/slam/io/scan_writers.hpp"
#include "featsense/slam/sim/prepared_simulation.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

struct Case {
  const char* preset;
  const char* scene;
  const char* path;
};

class SensorFromPoints : public ::testing::TestWithParam<Case> {};

/// The first scan of a `preset` sensor along the built-in `scene`'s named `path`.
Scan first_scan(const char* preset, const char* scene, const char* path,
                const MeasurementSettings& measurement) {
  SimulationRequest request;
  request.scene = scene;
  request.path = path;
  request.sensor = preset;
  request.measurement = measurement;
  request.frames = 1;
  const PreparedSimulation simulation(std::move(request));
  return simulation.simulator->simulate(0).scan;
}

TEST_P(SensorFromPoints, AKittiBinFolderIsReadAsTheSensorThatMadeIt) {
  const Case c = GetParam();
  const fs::path dir = test::scratch_dir(std::string("sensor_from_points_") + c.preset);
  const Scan truth = first_scan(c.preset, c.scene, c.path, MeasurementSettings::exact());
  write_scan_kitti_bin(truth, (dir / "000000.bin").string());

  const auto source = open_scan_folder(dir.string(), SourceOptions{});
  EXPECT_EQ(source->info().sensor.name, c.preset) << source->info().detail;
  const std::optional<Scan> back = source->next();
  ASSERT_TRUE(back);
  EXPECT_EQ(source->stats().warning_count, 0u);
  ASSERT_EQ(back->rows, truth.rows);
  ASSERT_EQ(back->cols, truth.cols);
  size_t valid = 0, same_cell = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (!truth.valid[i]) continue;
    ++valid;
    same_cell += back->valid[i] && (back->xyz[i] - truth.xyz[i]).norm() < 1e-4f ? 1 : 0;
  }
  ASSERT_GT(valid, 1000u);
  // In the corridor, a metre or two from the walls, 13 % of the points change their beam
  // where the beam origin offset is not counted.
  EXPECT_GE(static_cast<double>(same_cell), 0.999 * static_cast<double>(valid))
      << same_cell << " of " << valid << " points in their own cell";
}

// An OS1-128's points read as an HDL-64E (the preset that KITTI folders once were taken for):
// the upper half of every scan would be lost, so it is an error naming the share and the
// preset that fits, never a map of half scans.
TEST(SensorFromPoints, APresetThatDoesNotFitIsAnErrorNamingTheOneThatDoes) {
  const fs::path dir = test::scratch_dir("sensor_from_points_wrong_preset");
  write_scan_kitti_bin(first_scan("os1-128", "lab", "walk", MeasurementSettings{}),
                       (dir / "000000.bin").string());
  SourceOptions options;
  options.sensor_preset = "hdl64";
  try {
    open_scan_folder(dir.string(), options);
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("% of the points"), std::string::npos) << what;
    EXPECT_NE(what.find("outside the beams of sensor hdl64"), std::string::npos) << what;
    EXPECT_NE(what.find("presets whose beams they lie on: os1-128"), std::string::npos) << what;
  }
}

// A sensor no preset describes (40 beams spaced unevenly from +7 to -16 degrees, 1800
// columns: a Hesai Pandar40's layout) gets a model measured from its points: its beams at
// their elevations, its columns, every point in its own cell.
TEST(SensorFromPoints, ASensorNoPresetFitsIsMeasuredFromItsPoints) {
  std::vector<double> elevation_deg;
  for (int b = 0; b < 40; ++b) {
    // Dense in the middle (0.33 deg), sparse at the ends (1 deg), as such sensors are.
    elevation_deg.push_back(b < 5    ? 7.0 - b
                            : b < 35 ? 2.0 - 0.33 * (b - 5)
                                     : -8.0 - 1.6 * (b - 35));
  }
  constexpr int kColumns = 1800;
  Scan truth = Scan::allocate(40, kColumns);
  for (int r = 0; r < 40; ++r) {
    for (int c = 0; c < kColumns; ++c) {
      const double elevation = elevation_deg[static_cast<size_t>(r)] * M_PI / 180.0;
      const double azimuth = -2.0 * M_PI * c / kColumns;  // column c centred there, clockwise
      const double range = 5.0 + 20.0 * std::fabs(std::sin(0.37 * c + 1.3 * r));
      const size_t i = truth.index(r, c);
      truth.xyz[i] =
          Eigen::Vector3f(static_cast<float>(range * std::cos(elevation) * std::cos(azimuth)),
                          static_cast<float>(range * std::cos(elevation) * std::sin(azimuth)),
                          static_cast<float>(range * std::sin(elevation)));
      truth.range_m[i] = static_cast<float>(range);
      truth.valid[i] = 1;
    }
  }
  const fs::path dir = test::scratch_dir("sensor_from_points_measured");
  write_scan_kitti_bin(truth, (dir / "000000.bin").string());
  const auto source = open_scan_folder(dir.string(), SourceOptions{});
  const config::SensorModel& sensor = source->info().sensor;
  EXPECT_EQ(sensor.name, "measured-40-beams") << source->info().detail;
  EXPECT_EQ(sensor.columns, kColumns);
  ASSERT_EQ(sensor.elevation_rad.size(), 40u);
  for (size_t b = 0; b < 40; ++b)
    EXPECT_NEAR(sensor.elevation_rad[b] * 180.0 / M_PI, elevation_deg[b], 1e-3) << "beam " << b;
  const std::optional<Scan> back = source->next();
  ASSERT_TRUE(back);
  size_t same_cell = 0;
  for (size_t i = 0; i < truth.size(); ++i)
    same_cell += back->valid[i] && (back->xyz[i] - truth.xyz[i]).norm() < 1e-4f ? 1 : 0;
  EXPECT_GE(static_cast<double>(same_cell), 0.999 * static_cast<double>(truth.size()));
}

INSTANTIATE_TEST_SUITE_P(Presets, SensorFromPoints,
                         ::testing::Values(Case{"os1-128", "corridor", "walk"},
                                           Case{"vlp16", "parking", "drive"},
                                           Case{"hdl32", "parking", "drive"}),
                         [](const ::testing::TestParamInfo<Case>& param) {
                           std::string name = param.param.preset;
                           name.erase(std::remove(name.begin(), name.end(), '-'), name.end());
                           return name;
                         });

}  // namespace
}  // namespace featsense::slam
