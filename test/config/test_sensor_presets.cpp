#include <gtest/gtest.h>

#include <cmath>

#include "featsense/config/config_error.hpp"
#include "featsense/config/sensor_model.hpp"

namespace featsense::config {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(SensorPresets, AllPresetsOfTheDesignExistAndAreValid) {
  const std::vector<std::string> expected = {"hdl32",  "hdl64", "os0-128", "os1-128",
                                             "os1-64", "vlp16", "vlp32c",  "vls128"};
  EXPECT_EQ(sensor_preset_names(), expected);
  for (const auto& name : expected) {
    const SensorModel model = sensor_preset(name);
    EXPECT_NO_THROW(model.validate()) << name;
    EXPECT_EQ(model.name, name);
    EXPECT_EQ(static_cast<int>(model.elevation_rad.size()), model.beams) << name;
  }
}

TEST(SensorPresets, GeometryMatchesTheDataSheets) {
  const SensorModel vlp16 = sensor_preset("vlp16");
  EXPECT_EQ(vlp16.beams, 16);
  EXPECT_NEAR(vlp16.elevation_rad.front(), 15 * kDeg, 1e-12);
  EXPECT_NEAR(vlp16.elevation_rad[1] - vlp16.elevation_rad[0], -2 * kDeg, 1e-12);
  EXPECT_NEAR(vlp16.vertical_fov_rad(), 30 * kDeg, 1e-12);

  EXPECT_NEAR(sensor_preset("os1-128").vertical_fov_rad(), 45 * kDeg, 1e-12);
  // Velodyne's manuals: VLP-32C and VLS-128 from +15 to -25 deg.
  EXPECT_NEAR(sensor_preset("vlp32c").vertical_fov_rad(), 40 * kDeg, 1e-12);
  EXPECT_NEAR(sensor_preset("vls128").vertical_fov_rad(), 40 * kDeg, 1e-4);
  EXPECT_NEAR(sensor_preset("os0-128").vertical_fov_rad(), 90 * kDeg, 1e-12);
  EXPECT_EQ(sensor_preset("os1-64").beams, 64);
  const SensorModel hdl32 = sensor_preset("hdl32");
  EXPECT_NEAR(hdl32.vertical_fov_rad(), 41.34 * kDeg, 1e-9);

  // HDL-64E: 1/3 degree steps in the upper block, 1/2 degree in the lower.
  const SensorModel hdl64 = sensor_preset("hdl64");
  ASSERT_EQ(hdl64.beams, 64);
  EXPECT_NEAR(hdl64.elevation_rad[0] - hdl64.elevation_rad[1], kDeg / 3, 1e-5);
  EXPECT_NEAR(hdl64.elevation_rad[40] - hdl64.elevation_rad[41], 0.5 * kDeg, 1e-5);
  EXPECT_NEAR(hdl64.elevation_rad.back(), -24.33 * kDeg, 1e-5);
}

TEST(SensorPresets, NamesAreMatchedLooselyAndTyposGetAHint) {
  EXPECT_EQ(sensor_preset("OS-1-128").name, "os1-128");
  EXPECT_EQ(sensor_preset("VLP16").name, "vlp16");
  try {
    sensor_preset("hdl23");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean"), std::string::npos) << e.what();
  }
}

TEST(SensorPresets, InconsistentPresetDocumentsAreRejected) {
  const std::string base = "name: x\nbeams: 2\ncolumns: 10\nrate_hz: 10\nbeam_origin_offset_m: 0\n";
  EXPECT_THROW(
      parse_sensor_preset(base + "min_range_m: 0\nmax_range_m: 10\nelevation_deg: [1]\n", "t"),
      ConfigError);
  EXPECT_THROW(
      parse_sensor_preset(base + "min_range_m: 0\nmax_range_m: 10\nelevation_deg: [-1, 1]\n", "t"),
      ConfigError);
  EXPECT_THROW(
      parse_sensor_preset(base + "min_range_m: 5\nmax_range_m: 1\nvfov_deg: [10, -10]\n", "t"),
      ConfigError);
  EXPECT_THROW(parse_sensor_preset(base, "t"), ConfigError);  // no range limits
  EXPECT_NO_THROW(
      parse_sensor_preset(base + "min_range_m: 0\nmax_range_m: 10\nvfov_deg: [10, -10]\n", "t"));
}

}  // namespace
}  // namespace featsense::config
