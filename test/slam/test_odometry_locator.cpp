#include <gtest/gtest.h>

#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/io/box_room_source.hpp"
#include "featsense/slam/odometry/odometry_locator.hpp"

namespace featsense::slam::odometry {
namespace {

/// The built-in box room's scans (a sensor moving at 1 m/s), all of them.
std::vector<Scan> box_room_scans(int frames) {
  BoxRoomSettings settings = default_box_room();
  settings.frames = frames;
  auto source = make_box_room_source(settings);
  std::vector<Scan> scans;
  while (std::optional<Scan> scan = source->next()) scans.push_back(std::move(*scan));
  return scans;
}

TEST(OdometryLocator, DroppedFramesAndStampsGoingBackAreCountedWarnings) {
  const std::vector<Scan> scans = box_room_scans(10);
  ASSERT_EQ(scans.size(), 10u);
  auto locator = make_odometry_locator(config::Config{});
  std::vector<std::string> warnings;
  // Scans 0-3, then 7-9: three frames dropped; then scan 9 again (its stamp does not grow).
  for (const size_t i : {0u, 1u, 2u, 3u, 7u, 8u, 9u, 9u}) {
    std::string why;
    const std::optional<ScanPlacement> placed = locator->locate(scans[i], why);
    ASSERT_TRUE(placed.has_value());
    EXPECT_TRUE(placed->T_map_sensor.matrix().allFinite());
    if (!why.empty()) warnings.push_back(why);
  }
  EXPECT_EQ(locator->counts().time_jumps, 2u);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("4.0 scan periods"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("not after the last scan"), std::string::npos) << warnings[1];
  EXPECT_EQ(locator->counts().scans, 8u);
}

}  // namespace
}  // namespace featsense::slam::odometry
