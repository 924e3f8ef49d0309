#include <gtest/gtest.h>

#include <vector>

#include "featsense/tsdf/local_map_geometry.hpp"
#include "featsense/tsdf/tsdf_settings.hpp"

namespace featsense::tsdf {
namespace {

TEST(LocalMapGeometry, RingBufferLayoutIsABijectionWhereverTheMapIs) {
  LocalMapGeometry g;
  g.dim = {5, 7, 3};
  for (const Index3 origin : {Index3{0, 0, 0}, Index3{-13, 4, -2}, Index3{1000, -999, 77}}) {
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

TEST(LocalMapGeometry, TheMapIsCentredOnTheSensorWithAnOddSize) {
  TsdfSettings s;  // 40 x 40 x 15 m at 6.4 cm
  const Index3 dim = s.map_dim();
  EXPECT_EQ(dim.x, 625);
  EXPECT_EQ(dim.y, 625);
  EXPECT_EQ(dim.z, 235);  // 234.4 rounded up, then to odd
  const LocalMapGeometry g = centred_geometry(s, {3.0f, -2.0f, 1.0f});
  const Index3 centre = g.voxel_of({3.0f, -2.0f, 1.0f});
  EXPECT_EQ(centre.x - g.origin.x, (dim.x - 1) / 2);
  EXPECT_EQ(g.origin.x + dim.x - 1 - centre.x, (dim.x - 1) / 2);
  EXPECT_EQ(centre.z - g.origin.z, (dim.z - 1) / 2);
}

}  // namespace
}  // namespace featsense::tsdf
