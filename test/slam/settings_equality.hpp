#pragma once
// Field-by-field equality of the registration's settings, for the tests that check a room's
// defaults against the configuration's.

#include <gtest/gtest.h>

#include "featsense/slam/refine/vgicp.hpp"

namespace featsense::test {

inline void expect_same_vgicp(const slam::refine::VgicpSettings& a,
                              const slam::refine::VgicpSettings& b) {
  EXPECT_EQ(a.voxel_sizes_m, b.voxel_sizes_m);
  EXPECT_EQ(a.max_iterations, b.max_iterations);
  EXPECT_EQ(a.step_tolerance_m, b.step_tolerance_m);
  EXPECT_EQ(a.inlier_distance_m, b.inlier_distance_m);
  EXPECT_EQ(a.fitness_voxel_m, b.fitness_voxel_m);
}

}  // namespace featsense::test
