#include <gtest/gtest.h>

#include <vector>

#include "featsense/tsdf/local_map_geometry.hpp"
#include "featsense/tsdf/tsdf_settings.hpp"

namespace featsense::tsdf {
namespace {

TEST(LocalMapGeometry, RingBufferLayoutIsABijectionWhereverTheMapIs) {
  LocalMapGeometry g;
  g.dim = {3 * kBrickSize, 5 * kBrickSize, kBrickSize};
  for (const Index3 origin : {Index3{0, 0, 0}, Index3{-16, 8, -24}, Index3{1000, -1000, 80}}) {
    g.origin = origin;
    std::vector<int> hits(g.voxel_count(), 0);
    for (int z = 0; z < g.dim.z; ++z) {
      for (int y = 0; y < g.dim.y; ++y) {
        for (int x = 0; x < g.dim.x; ++x) {
          const Index3 v{origin.x + x, origin.y + y, origin.z + z};
          ASSERT_TRUE(g.contains(v));
          ++hits[g.linear(v)];
        }
      }
    }
    for (int h : hits) EXPECT_EQ(h, 1);
    EXPECT_FALSE(g.contains({origin.x - 1, origin.y, origin.z}));
    EXPECT_FALSE(g.contains({origin.x, origin.y + g.dim.y, origin.z}));
  }
}

TEST(LocalMapGeometry, VoxelsAreAnchoredAtTheMapOrigin) {
  LocalMapGeometry g;
  g.voxel_size_m = 0.1f;
  EXPECT_EQ(g.voxel_of({0.05f, -0.05f, 0.25f}).x, 0);
  EXPECT_EQ(g.voxel_of({0.05f, -0.05f, 0.25f}).y, -1);
  EXPECT_EQ(g.voxel_of({0.05f, -0.05f, 0.25f}).z, 2);
  EXPECT_FLOAT_EQ(g.centre_of({-1, 0, 2}).x, -0.05f);
  EXPECT_FLOAT_EQ(g.centre_of({-1, 0, 2}).z, 0.25f);
}

TEST(LocalMapGeometry, TheMapIsCentredOnTheSensorsBrickWithAnOddBrickCount) {
  TsdfSettings s;  // 40 x 40 x 15 m at 6.4 cm
  const Index3 dim = s.map_dim();
  EXPECT_EQ(dim.x, 79 * kBrickSize);  // 625 voxels, 78.1 bricks, rounded up to 79 (odd)
  EXPECT_EQ(dim.y, 79 * kBrickSize);
  EXPECT_EQ(dim.z, 31 * kBrickSize);  // 235 voxels, 29.4 bricks, up to 30, then to odd
  for (const Vec3 sensor : {Vec3{3.0f, -2.0f, 1.0f}, Vec3{-100.3f, 0.01f, -7.7f}}) {
    const LocalMapGeometry g = centred_geometry(s, sensor);
    const Index3 centre = g.voxel_of(sensor);
    EXPECT_EQ(g.origin.x % kBrickSize, 0);
    EXPECT_EQ(g.origin.z % kBrickSize, 0);
    EXPECT_EQ(brick_of(centre.x) - brick_of(g.origin.x), (g.bricks().x - 1) / 2);
    EXPECT_EQ(brick_of(g.origin.y + dim.y - 1) - brick_of(centre.y), (g.bricks().y - 1) / 2);
    EXPECT_EQ(brick_of(centre.z) - brick_of(g.origin.z), (g.bricks().z - 1) / 2);
  }
}

TEST(LocalMapGeometry, BricksHoldNeighbouringVoxelsTogether) {
  LocalMapGeometry g;
  g.dim = {3 * kBrickSize, 3 * kBrickSize, 3 * kBrickSize};
  g.origin = {-8, -8, -8};
  const size_t first = g.linear({0, 0, 0});
  EXPECT_EQ(first % kBrickVoxels, 0u);
  for (int32_t z = 0; z < kBrickSize; ++z) {
    for (int32_t y = 0; y < kBrickSize; ++y) {
      for (int32_t x = 0; x < kBrickSize; ++x) {
        ASSERT_LT(g.linear({x, y, z}) - first, static_cast<size_t>(kBrickVoxels));
      }
    }
  }
  EXPECT_EQ(brick_of(-1), -1);
  EXPECT_EQ(brick_of(-8), -1);
  EXPECT_EQ(brick_of(-9), -2);
  EXPECT_EQ(brick_of(7), 0);
}

}  // namespace
}  // namespace featsense::tsdf
