// Veil points between a foreground edge and the surface behind it are dropped; edges,
// surfaces seen at a grazing angle and isolated returns stay.

#include <gtest/gtest.h>

#include <vector>

#include "featsense/slam/preprocess/mixed_pixel_filter.hpp"

namespace featsense::slam {
namespace {

/// One row of the given ranges (0 = no return), the rest of the scan empty.
Scan row_of(const std::vector<float>& ranges) {
  Scan scan = Scan::allocate(2, static_cast<int>(ranges.size()));
  for (size_t c = 0; c < ranges.size(); ++c) {
    if (ranges[c] <= 0.0f) continue;
    scan.valid[c] = 1;
    scan.range_m[c] = ranges[c];
    scan.xyz[c] = Eigen::Vector3f(ranges[c], 0.0f, 0.0f);
  }
  return scan;
}

TEST(MixedPixelFilter, DropsPointsBetweenAnEdgeAndTheSurfaceBehind) {
  // A box edge at 3 m in front of a wall at 6 m; column 4 merged both echoes (4.2 m).
  Scan scan = row_of({3.0f, 3.0f, 3.01f, 3.0f, 4.2f, 6.0f, 6.02f, 6.0f, 6.01f, 6.0f});
  EXPECT_EQ(drop_mixed_pixels(scan), 1u);
  EXPECT_EQ(scan.valid[4], 0);
  EXPECT_EQ(scan.valid_count(), 9u);
}

TEST(MixedPixelFilter, KeepsEdgesSlopesAndLoneReturns) {
  // The edge cell itself (3.05 m, within the margin of the foreground) stays.
  Scan edge = row_of({3.0f, 3.0f, 3.0f, 3.05f, 6.0f, 6.0f, 6.0f, 6.0f});
  EXPECT_EQ(drop_mixed_pixels(edge), 0u);
  // A wall at a grazing angle: the range grows evenly by 0.5 m per column.
  Scan slope = row_of({10.0f, 10.5f, 11.0f, 11.5f, 12.0f, 12.5f, 13.0f, 13.5f});
  EXPECT_EQ(drop_mixed_pixels(slope), 0u);
  // Neighbours without a return: nothing to judge by.
  Scan sparse = row_of({3.0f, 0.0f, 4.5f, 6.0f, 6.0f, 0.0f, 3.0f, 3.0f});
  EXPECT_EQ(drop_mixed_pixels(sparse), 0u);
  // A small step (0.2 m) is noise or a ledge, not a depth edge.
  Scan step = row_of({3.0f, 3.0f, 3.0f, 3.1f, 3.2f, 3.2f, 3.2f, 3.2f});
  EXPECT_EQ(drop_mixed_pixels(step), 0u);
}

TEST(MixedPixelFilter, ColumnsWrapAroundTheRevolution) {
  // The veil point is column 0; its left neighbours are the last columns.
  Scan scan = row_of({4.5f, 6.0f, 6.0f, 6.0f, 6.0f, 3.0f, 3.0f});
  EXPECT_EQ(drop_mixed_pixels(scan), 1u);
  EXPECT_EQ(scan.valid[0], 0);
}

}  // namespace
}  // namespace featsense::slam
