#include <gtest/gtest.h>

#include <cmath>

#include "featsense/slam/io/box_room_source.hpp"

namespace featsense::slam {
namespace {

/// Distance of a map point to the nearest face of the room's box.
double distance_to_nearest_wall(const Eigen::Vector3d& p, const BoxRoomSettings& s) {
  double d = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    d = std::min(
        {d, std::abs(p[axis] - s.room_min_m[axis]), std::abs(p[axis] - s.room_max_m[axis])});
  }
  return d;
}

TEST(BoxRoomSource, EveryPointLiesOnAWallOnceUndistortedWithItsTime) {
  BoxRoomSettings settings = default_box_room();
  settings.frames = 2;
  auto source = make_box_room_source(settings);
  int frames = 0;
  while (auto scan = source->next()) {
    ASSERT_EQ(scan->rows, 128);
    ASSERT_EQ(scan->cols, 1024);
    EXPECT_EQ(scan->valid_count(), scan->size());  // a closed room returns every beam
    const double frame_start_s = frames / settings.sensor.rate_hz;
    double worst_undistorted = 0.0;
    double worst_with_frame_pose = 0.0;
    for (size_t i = 0; i < scan->size(); ++i) {
      const Eigen::Vector3d local = scan->xyz[i].cast<double>();
      EXPECT_NEAR(local.norm(), scan->range_m[i], 1e-4);
      const double t = frame_start_s + scan->time_offset_s[i];
      worst_undistorted =
          std::max(worst_undistorted,
                   distance_to_nearest_wall(box_room_pose(settings, t) * local, settings));
      worst_with_frame_pose = std::max(
          worst_with_frame_pose,
          distance_to_nearest_wall(box_room_pose(settings, frame_start_s) * local, settings));
    }
    EXPECT_LT(worst_undistorted, 1e-4);
    // Without the per-point time the motion (1 m/s over 0.1 s) shows as distortion.
    EXPECT_GT(worst_with_frame_pose, 0.05);
    ++frames;
  }
  EXPECT_EQ(frames, 2);
  EXPECT_EQ(source->stats().frames_read, 2u);
}

TEST(BoxRoomSource, ElevationsOfTheRowsAreThoseOfTheSensorModel) {
  BoxRoomSettings settings = default_box_room();
  settings.frames = 1;
  auto scan = make_box_room_source(settings)->next();
  ASSERT_TRUE(scan.has_value());
  for (int row = 0; row < scan->rows; row += 7) {
    const Eigen::Vector3f& p = scan->xyz[scan->index(row, 100)];
    const double elevation = std::atan2(p.z(), std::hypot(p.x(), p.y()));
    EXPECT_NEAR(elevation, settings.sensor.elevation_rad[static_cast<size_t>(row)], 1e-5);
  }
  // Column 0 looks along +x, columns turn clockwise (towards -y) with time.
  const Eigen::Vector3f& first = scan->xyz[scan->index(64, 0)];
  const Eigen::Vector3f& quarter = scan->xyz[scan->index(64, 256)];
  EXPECT_GT(first.x(), 0.0f);
  EXPECT_NEAR(first.y(), 0.0f, 1e-4f);
  EXPECT_LT(quarter.y(), 0.0f);
  EXPECT_LT(scan->time_offset_s[scan->index(64, 0)], scan->time_offset_s[scan->index(64, 256)]);
}

}  // namespace
}  // namespace featsense::slam
