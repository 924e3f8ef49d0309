#include "featsense/storage/vdb_io.hpp"

#include <gtest/gtest.h>

#include <map>

#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "storage/storage_test_util.hpp"

namespace featsense::storage {
namespace {

using test::make_chunk;
using test::test_metadata;

/// A chunk with the extremes of the encoding: +/- tau, the smallest step, weights 1/64 and
/// the largest weight.
Chunk extreme_chunk() {
  Chunk chunk;
  const int16_t values[] = {32767, -32767, 1, -1, 0, 12345};
  const uint16_t weights[] = {1, 65535, 64, 640};
  std::size_t i = 0;
  for (const int16_t value : values)
    for (const uint16_t weight : weights) chunk.voxels[i++ * 997] = tsdf::pack({value, weight});
  return chunk;
}

TEST(VdbIo, StoreToVdbToStoreIsLossless) {
  const auto dir = test::scratch_dir("vdb_round_trip");
  std::map<ChunkKey, Chunk> expected = {
      {{0, 0, 0}, make_chunk(1)}, {{-1, 2, -3}, make_chunk(2)}, {{5, -7, 0}, extreme_chunk()}};
  std::size_t observed = 0;
  for (const auto& [key, chunk] : expected)
    for (const uint32_t bits : chunk.voxels) observed += (bits >> 16) != 0u ? 1 : 0;
  {
    Hdf5ChunkStore source(dir / "a.h5", OpenMode::kCreate, test_metadata());
    for (const auto& [key, chunk] : expected) source.write(key, chunk);
    const VdbExportStats stats = export_vdb(source, dir / "map.vdb");
    EXPECT_EQ(stats.chunks, expected.size());
    EXPECT_EQ(stats.active_voxels, observed);
  }
  Hdf5ChunkStore target(dir / "b.h5", OpenMode::kCreate, test_metadata());
  const VdbExportStats stats = import_vdb(dir / "map.vdb", target);
  EXPECT_EQ(stats.active_voxels, observed);
  ASSERT_EQ(target.keys().size(), expected.size());
  for (const auto& [key, chunk] : expected) {
    const auto read = target.read(key);
    ASSERT_TRUE(read.has_value());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < kChunkVoxels; ++i) differing += read->voxels[i] != chunk.voxels[i];
    EXPECT_EQ(differing, 0u) << key.x << " " << key.y << " " << key.z;
  }
}

TEST(VdbIo, ImportChecksVoxelSizeAndTau) {
  const auto dir = test::scratch_dir("vdb_mismatch");
  {
    Hdf5ChunkStore source(dir / "a.h5", OpenMode::kCreate, test_metadata());
    source.write({0, 0, 0}, make_chunk(1));
    export_vdb(source, dir / "map.vdb");
  }
  MapMetadata other = test_metadata();
  other.truncation_m = 0.3;
  Hdf5ChunkStore target(dir / "b.h5", OpenMode::kCreate, other);
  try {
    import_vdb(dir / "map.vdb", target);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("0.6"), std::string::npos) << message;
    EXPECT_NE(message.find("0.3"), std::string::npos) << message;
  }
  EXPECT_THROW(import_vdb(dir / "missing.vdb", target), std::runtime_error);
}

TEST(VdbIo, MetadataIsReadWithoutTheVoxels) {
  const auto dir = test::scratch_dir("vdb_metadata");
  {
    Hdf5ChunkStore source(dir / "a.h5", OpenMode::kCreate, test_metadata());
    source.write({0, 0, 0}, make_chunk(1));
    export_vdb(source, dir / "map.vdb");
  }
  const MapMetadata read = read_vdb_metadata(dir / "map.vdb");
  EXPECT_DOUBLE_EQ(read.voxel_size_m, test_metadata().voxel_size_m);
  EXPECT_DOUBLE_EQ(read.truncation_m, test_metadata().truncation_m);
  EXPECT_THROW(read_vdb_metadata(dir / "missing.vdb"), std::runtime_error);
  EXPECT_THROW(read_vdb_metadata(dir / "a.h5"), std::runtime_error);
}

}  // namespace
}  // namespace featsense::storage
