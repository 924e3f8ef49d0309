// Two maps compared chunk by chunk and voxel by voxel (featsense eval maps): counts of equal,
// differing and unshared chunks, and the largest differences in metres and weight.

#include <gtest/gtest.h>

#include "featsense/storage/map_comparison.hpp"
#include "featsense/storage/memory_chunk_store.hpp"
#include "featsense/tsdf/voxel.hpp"

namespace featsense::storage {
namespace {

MapMetadata grid(double voxel_m = 0.064, double tau_m = 0.25) {
  MapMetadata m;
  m.voxel_size_m = voxel_m;
  m.truncation_m = tau_m;
  return m;
}

uint32_t voxel(int16_t value, uint16_t weight) { return tsdf::pack({value, weight}); }

TEST(MapComparison, CountsChunksAndTheLargestDifferences) {
  MemoryChunkStore a(grid());
  MemoryChunkStore b(grid());
  Chunk same;
  same.at(1, 2, 3) = voxel(100, 64);
  a.write({0, 0, 0}, same);
  b.write({0, 0, 0}, same);
  Chunk first;
  first.at(0, 0, 0) = voxel(1000, 640);
  first.at(5, 5, 5) = voxel(-20, 64);
  Chunk second = first;
  second.at(0, 0, 0) = voxel(1000 + 3277, 512);  // 0.025 m and 2 measurements apart
  second.at(9, 9, 9) = voxel(7, 64);             // observed in the second only
  a.write({1, 0, 0}, first);
  b.write({1, 0, 0}, second);
  a.write({0, 5, 0}, same);  // the first's only
  b.write({0, 0, 7}, same);
  b.write({0, 0, 8}, same);

  const MapDifference d = compare_maps(a, b);
  EXPECT_FALSE(d.identical());
  EXPECT_EQ(d.chunks_equal, 1u);
  EXPECT_EQ(d.chunks_differing, 1u);
  EXPECT_EQ(d.chunks_only_first, 1u);
  EXPECT_EQ(d.chunks_only_second, 2u);
  EXPECT_EQ(d.voxels_differing, 2u);
  EXPECT_EQ(d.voxels_observed_in_one, 1u);
  EXPECT_NEAR(d.largest_value_difference_m, 3277 * 0.25 / 32767, 1e-12);
  EXPECT_DOUBLE_EQ(d.largest_weight_difference, 2.0);
}

TEST(MapComparison, AMapIsIdenticalToItself) {
  MemoryChunkStore a(grid());
  Chunk chunk;
  chunk.at(3, 3, 3) = voxel(-5, 100);
  a.write({2, -1, 0}, chunk);
  EXPECT_TRUE(compare_maps(a, a).identical());
  EXPECT_EQ(compare_maps(a, a).chunks_equal, 1u);
}

TEST(MapComparison, MapsOfOtherGridsAreAnError) {
  MemoryChunkStore a(grid(0.064));
  MemoryChunkStore b(grid(0.05));
  EXPECT_THROW(compare_maps(a, b), std::runtime_error);
}

}  // namespace
}  // namespace featsense::storage
