#include "featsense/storage/hdf5_chunk_store.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <map>
#include <random>

#include "common/test_data.hpp"
#include "storage/storage_test_util.hpp"

namespace featsense::storage {
namespace {

using test::make_chunk;
using test::test_metadata;

/// Keys spread over all octants, negatives included, with their chunk seeds.
std::map<ChunkKey, uint32_t> random_keys(std::size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int32_t> coordinate(-40, 40);
  std::map<ChunkKey, uint32_t> keys;
  while (keys.size() < count) keys[{coordinate(rng), coordinate(rng), coordinate(rng)}] = rng();
  return keys;
}

TEST(Hdf5ChunkStore, RoundTripManyKeys) {
  const auto path = test::scratch_dir("store_round_trip") / "map.h5";
  const auto expected = random_keys(60, 1);
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
    for (const auto& [key, seed] : expected) store.write(key, make_chunk(seed));
    store.close();
  }
  Hdf5ChunkStore store(path);
  const auto keys = store.keys();
  ASSERT_EQ(keys.size(), expected.size());
  for (const auto& [key, seed] : expected) {
    const auto chunk = store.read(key);
    ASSERT_TRUE(chunk.has_value()) << key.x << " " << key.y << " " << key.z;
    EXPECT_TRUE(*chunk == make_chunk(seed)) << key.x << " " << key.y << " " << key.z;
  }
  const MapMetadata& m = store.metadata();
  EXPECT_EQ(m.voxel_size_m, 0.064);
  EXPECT_EQ(m.truncation_m, 0.6);
  EXPECT_EQ(m.value_scale, 32767);
  EXPECT_EQ(m.weight_scale, 64);
  EXPECT_EQ(m.chunk_size, 64);
  EXPECT_EQ(m.max_weight, 10.0);
  EXPECT_EQ(m.sensor, "ouster-os1-64");
  EXPECT_EQ(m.config_yaml, test_metadata().config_yaml);
  EXPECT_EQ(store.journal_bytes(), 8u);  // only the journal's magic after the checkpoint
}

TEST(Hdf5ChunkStore, AbsentChunksStayAbsent) {
  const auto path = test::scratch_dir("store_absent") / "map.h5";
  Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
  store.write({0, 0, 0}, make_chunk(7));
  store.write({1, 0, 0}, Chunk{});  // empty: never stored
  EXPECT_FALSE(store.read({1, 0, 0}).has_value());
  EXPECT_FALSE(store.read({-1, 0, 0}).has_value());
  store.checkpoint();
  // Removing a durable chunk by writing it empty.
  store.write({0, 0, 0}, Chunk{});
  store.close();
  Hdf5ChunkStore reopened(path);
  EXPECT_TRUE(reopened.keys().empty());
  EXPECT_FALSE(reopened.read({0, 0, 0}).has_value());
}

TEST(Hdf5ChunkStore, LruEvictionKeepsData) {
  const auto path = test::scratch_dir("store_lru") / "map.h5";
  StoreSettings settings;
  settings.cache_bytes = 2 * kChunkBytes;  // two chunks in memory
  const auto expected = random_keys(12, 2);
  Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), settings);
  for (const auto& [key, seed] : expected) store.write(key, make_chunk(seed));
  // Overwrite half of them after they were evicted: the newest version must win.
  std::map<ChunkKey, uint32_t> latest = expected;
  int i = 0;
  for (auto& [key, seed] : latest)
    if (i++ % 2 == 0) {
      seed += 1000;
      store.write(key, make_chunk(seed));
    }
  for (const auto& [key, seed] : latest) EXPECT_TRUE(*store.read(key) == make_chunk(seed));
  store.checkpoint();
  for (const auto& [key, seed] : latest) EXPECT_TRUE(*store.read(key) == make_chunk(seed));
  store.close();
  Hdf5ChunkStore reopened(path, settings);
  for (const auto& [key, seed] : latest) EXPECT_TRUE(*reopened.read(key) == make_chunk(seed));
}

TEST(Hdf5ChunkStore, AppendContinuesAMap) {
  const auto path = test::scratch_dir("store_append") / "map.h5";
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
    store.write({1, 2, 3}, make_chunk(1));
  }
  {
    Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata());
    store.write({-1, -2, -3}, make_chunk(2));
  }
  Hdf5ChunkStore store(path);
  EXPECT_EQ(store.keys().size(), 2u);
  EXPECT_TRUE(*store.read({1, 2, 3}) == make_chunk(1));
  EXPECT_TRUE(*store.read({-1, -2, -3}) == make_chunk(2));
  EXPECT_THROW(store.write({0, 0, 0}, make_chunk(3)), std::logic_error);
}

TEST(Hdf5ChunkStore, MetadataMismatchNamesBothValues) {
  const auto path = test::scratch_dir("store_mismatch") / "map.h5";
  { Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata()); }
  MapMetadata other = test_metadata();
  other.voxel_size_m = 0.1;
  try {
    Hdf5ChunkStore store(path, OpenMode::kAppend, other);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("voxel size"), std::string::npos) << message;
    EXPECT_NE(message.find("0.064"), std::string::npos) << message;
    EXPECT_NE(message.find("0.1"), std::string::npos) << message;
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
  }
  other = test_metadata();
  other.truncation_m = 0.3;
  EXPECT_THROW(Hdf5ChunkStore(path, OpenMode::kAppend, other), std::runtime_error);
}

TEST(Hdf5ChunkStore, CreateRefusesAnExistingMapUnlessOverwriting) {
  const auto path = test::scratch_dir("store_exists") / "map.h5";
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
    store.write({0, 0, 0}, make_chunk(1));
  }
  EXPECT_THROW(Hdf5ChunkStore(path, OpenMode::kCreate, test_metadata()), std::runtime_error);
  { Hdf5ChunkStore store(path, OpenMode::kCreateOverwrite, test_metadata()); }
  Hdf5ChunkStore store(path);
  EXPECT_TRUE(store.keys().empty());
}

void expect_create_fails_naming(const std::filesystem::path& path) {
  try {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
    ADD_FAILURE() << "no error for " << path;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
}

TEST(Hdf5ChunkStore, UnwritablePathFailsAtOnce) {
  const auto dir = test::scratch_dir("store_unwritable");
  // A regular file where the directory should be: unwritable even for root.
  { std::ofstream(dir / "not_a_dir") << "x"; }
  expect_create_fails_naming(dir / "not_a_dir" / "map.h5");
  expect_create_fails_naming(dir / "missing" / "map.h5");
  if (::geteuid() != 0) {  // root ignores permission bits
    std::filesystem::create_directory(dir / "read_only");
    std::filesystem::permissions(
        dir / "read_only", std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    expect_create_fails_naming(dir / "read_only" / "map.h5");
    std::filesystem::permissions(dir / "read_only", std::filesystem::perms::owner_all);
  }
}

TEST(Hdf5ChunkStore, TrajectoryRoundTrip) {
  const auto path = test::scratch_dir("store_trajectory") / "map.h5";
  std::vector<TrajectoryPose> poses;
  for (int i = 0; i < 5; ++i)
    poses.push_back({0.1 * i, 1.0 * i, -2.0 * i, 0.5, 0.0, 0.0, std::sqrt(0.5), std::sqrt(0.5)});
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
    store.write_trajectory(poses);
  }
  Hdf5ChunkStore store(path);
  const auto read = store.read_trajectory();
  ASSERT_EQ(read.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(read[i].t_s, poses[i].t_s);
    EXPECT_EQ(read[i].y, poses[i].y);
    EXPECT_EQ(read[i].qw, poses[i].qw);
  }
}

}  // namespace
}  // namespace featsense::storage
