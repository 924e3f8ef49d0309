#include "featsense/storage/chunk.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "featsense/tsdf/voxel.hpp"

namespace featsense::storage {
namespace {

TEST(Chunk, CoordinateIsFloorDivision) {
  for (int64_t g = -300; g <= 300; ++g) {
    const auto expected = static_cast<int32_t>(std::floor(static_cast<double>(g) / 64.0));
    EXPECT_EQ(chunk_coordinate(g), expected) << g;
  }
  const ChunkKey key = chunk_of_voxel(-1, 64, -65);
  EXPECT_EQ(key, (ChunkKey{-1, 1, -2}));
}

TEST(Chunk, XIsFastest) {
  EXPECT_EQ(Chunk::index(1, 0, 0), 1u);
  EXPECT_EQ(Chunk::index(0, 1, 0), 64u);
  EXPECT_EQ(Chunk::index(0, 0, 1), 4096u);
  EXPECT_EQ(Chunk::index(63, 63, 63), kChunkVoxels - 1);
}

TEST(Chunk, EmptyMeansNoWeight) {
  Chunk chunk;
  EXPECT_TRUE(is_empty(chunk));
  // A value without weight is still "never observed".
  chunk.at(5, 6, 7) = tsdf::pack(tsdf::Voxel{1234, 0});
  EXPECT_TRUE(is_empty(chunk));
  chunk.at(5, 6, 7) = tsdf::pack(tsdf::Voxel{1234, 1});
  EXPECT_FALSE(is_empty(chunk));
}

}  // namespace
}  // namespace featsense::storage
