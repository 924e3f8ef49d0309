// A map spliced from two: the newer map's records and chosen chunks, the older map's other
// chunks, copied as stored (still compressed) where a map holds them in its .h5.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "storage/storage_test_util.hpp"

namespace featsense::storage {
namespace {

namespace fs = std::filesystem;
using test::make_chunk;
using test::make_keyframe;
using test::make_session;
using test::test_metadata;

/// Seeds of the older map's chunks and of the newer map's (other contents at some keys).
const std::vector<std::pair<ChunkKey, uint32_t>> kOlder = {
    {{0, 0, 0}, 1}, {{1, 0, 0}, 2}, {{2, 0, 0}, 3}, {{0, 1, 0}, 4}, {{-3, 2, 1}, 5}};
const std::vector<std::pair<ChunkKey, uint32_t>> kNewer = {
    {{1, 0, 0}, 12}, {{2, 0, 0}, 13}, {{0, 1, 0}, 14}, {{5, 5, 5}, 15}};
/// The chunks taken from the newer map: (0,1,0) is not, so the older one's stays; (-3,2,1)
/// is, so the older one's is dropped (the newer map holds none there).
const std::set<ChunkKey> kChanged = {{1, 0, 0}, {2, 0, 0}, {5, 5, 5}, {-3, 2, 1}};

bool changed(const ChunkKey& key) { return kChanged.count(key) > 0; }

fs::path write_map(const fs::path& path, const std::vector<std::pair<ChunkKey, uint32_t>>& chunks,
                   uint32_t session, int deflate_level = 1) {
  StoreSettings settings;
  settings.deflate_level = deflate_level;
  Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), settings);
  for (const auto& [key, seed] : chunks) store.write(key, make_chunk(seed));
  store.write_trajectory({{1.0 * session, 2.0, 3.0, 4.0, 0.0, 0.0, 0.0, 1.0}});
  store.write_sessions({make_session(session, "first")});
  store.write_keyframes({make_keyframe(session, 0), make_keyframe(session, 1)});
  store.close();
  return path;
}

/// Bytes a chunk dataset takes in the file: what its compression made of it.
hsize_t stored_size(const fs::path& map, const ChunkKey& key) {
  const hid_t file = H5Fopen(map.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const std::string name = "/chunks/" + std::to_string(key.x) + "_" + std::to_string(key.y) + "_" +
                           std::to_string(key.z);
  const hid_t dataset = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  const hsize_t size = dataset < 0 ? 0 : H5Dget_storage_size(dataset);
  if (dataset >= 0) H5Dclose(dataset);
  H5Fclose(file);
  return size;
}

/// Both maps opened read-only, as a closed map is spliced.
SpliceCounts splice_files(const fs::path& into, const fs::path& newer_path,
                          const fs::path& older_path) {
  const Hdf5ChunkStore older(older_path);
  const Hdf5ChunkStore newer(newer_path);
  return splice_maps(into, newer, changed, older);
}

TEST(SpliceMaps, TakesTheChosenChunksFromTheNewerAndTheRestFromTheOlder) {
  const fs::path dir = test::scratch_dir("splice_maps");
  const fs::path older_path = write_map(dir / "older.h5", kOlder, 1);
  const fs::path newer_path = write_map(dir / "newer.h5", kNewer, 2);
  const fs::path into = dir / "spliced.h5";
  const SpliceCounts counts = splice_files(into, newer_path, older_path);
  EXPECT_EQ(counts.from_newer, 3u);  // (1,0,0), (2,0,0), (5,5,5)
  EXPECT_EQ(counts.from_older, 2u);  // (0,0,0), (0,1,0)
  Hdf5ChunkStore spliced(into);
  const std::vector<ChunkKey> expected_keys = {
      {0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {2, 0, 0}, {5, 5, 5}};
  std::vector<ChunkKey> keys = spliced.keys();
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(keys, expected_keys);
  EXPECT_TRUE(*spliced.read({0, 0, 0}) == make_chunk(1));
  EXPECT_TRUE(*spliced.read({0, 1, 0}) == make_chunk(4));
  EXPECT_TRUE(*spliced.read({1, 0, 0}) == make_chunk(12));
  EXPECT_TRUE(*spliced.read({2, 0, 0}) == make_chunk(13));
  EXPECT_TRUE(*spliced.read({5, 5, 5}) == make_chunk(15));
  // Every record is the newer map's.
  ASSERT_EQ(spliced.read_trajectory().size(), 1u);
  EXPECT_EQ(spliced.read_trajectory()[0].t_s, 2.0);
  ASSERT_EQ(spliced.read_sessions().size(), 1u);
  EXPECT_TRUE(test::same_session(spliced.read_sessions()[0], make_session(2, "first")));
  const std::vector<StoredKeyframe> keyframes = spliced.read_keyframes();
  ASSERT_EQ(keyframes.size(), 2u);
  EXPECT_TRUE(test::same_keyframe(keyframes[1], make_keyframe(2, 1)));
}

TEST(SpliceMaps, CopiesChunksAsStoredWithoutEncodingThemAgain) {
  // The older map compressed at level 9, the newer at level 1: a kept chunk encoded again
  // would take level 1's larger size.
  const fs::path dir = test::scratch_dir("splice_maps_as_stored");
  const fs::path older_path = write_map(dir / "older.h5", kOlder, 1, 9);
  const fs::path newer_path = write_map(dir / "newer.h5", kNewer, 2, 1);
  const fs::path level_one = write_map(dir / "level_one.h5", kOlder, 1, 1);
  ASSERT_LT(stored_size(older_path, {0, 0, 0}), stored_size(level_one, {0, 0, 0}));
  const fs::path into = dir / "spliced.h5";
  splice_files(into, newer_path, older_path);
  EXPECT_EQ(stored_size(into, {0, 0, 0}), stored_size(older_path, {0, 0, 0}));
  EXPECT_EQ(stored_size(into, {1, 0, 0}), stored_size(newer_path, {1, 0, 0}));
}

TEST(SpliceMaps, ChunksStillInAJournalAreTakenToo) {
  const fs::path dir = test::scratch_dir("splice_maps_journal");
  const fs::path older_path = write_map(dir / "older.h5", kOlder, 1);
  {
    // Flushed but not checkpointed: the chunk lives in the journal only.
    Hdf5ChunkStore older(older_path, OpenMode::kAppend, test_metadata(), test::no_checkpoint());
    older.write({0, 0, 0}, make_chunk(21));
    older.close();
  }
  const fs::path newer_path = write_map(dir / "newer.h5", kNewer, 2);
  const fs::path into = dir / "spliced.h5";
  splice_files(into, newer_path, older_path);
  Hdf5ChunkStore spliced(into);
  EXPECT_TRUE(*spliced.read({0, 0, 0}) == make_chunk(21));
}

TEST(SpliceMaps, ReplacesAMapAndDropsItsJournal) {
  const fs::path dir = test::scratch_dir("splice_maps_replace");
  const fs::path into = dir / "spliced.h5";
  {
    // A map at `into` whose journal holds a chunk the new map must not get.
    Hdf5ChunkStore stale(into, OpenMode::kCreate, test_metadata(), test::no_checkpoint());
    stale.write({9, 9, 9}, make_chunk(99));
    stale.close();
  }
  ASSERT_TRUE(fs::exists(test::journal_of(into)));
  const fs::path older_path = write_map(dir / "older.h5", kOlder, 1);
  const fs::path newer_path = write_map(dir / "newer.h5", kNewer, 2);
  splice_files(into, newer_path, older_path);
  Hdf5ChunkStore spliced(into);
  EXPECT_FALSE(spliced.read({9, 9, 9}).has_value());
  EXPECT_EQ(spliced.keys().size(), 5u);
}

TEST(SpliceMaps, RefusesUnflushedSourcesOtherGridsAndASourceAsTarget) {
  const fs::path dir = test::scratch_dir("splice_maps_refused");
  const fs::path older_path = write_map(dir / "older.h5", kOlder, 1);
  const fs::path newer_path = write_map(dir / "newer.h5", kNewer, 2);
  {
    const Hdf5ChunkStore older(older_path);
    Hdf5ChunkStore newer(newer_path, OpenMode::kAppend, test_metadata());
    newer.write({7, 7, 7}, make_chunk(7));
    EXPECT_THROW(splice_maps(dir / "a.h5", newer, changed, older), std::logic_error);
    newer.flush();
    EXPECT_NO_THROW(splice_maps(dir / "a.h5", newer, changed, older));
    EXPECT_THROW(splice_maps(older_path, newer, changed, older), std::invalid_argument);
  }
  MapMetadata coarse = test_metadata();
  coarse.voxel_size_m = 0.128;
  const fs::path coarse_path = dir / "coarse.h5";
  Hdf5ChunkStore(coarse_path, OpenMode::kCreate, coarse).close();
  const Hdf5ChunkStore older(coarse_path);
  const Hdf5ChunkStore newer(newer_path);
  try {
    splice_maps(dir / "b.h5", newer, changed, older);
    FAIL() << "maps of two voxel sizes were spliced";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("0.128 m"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("0.064 m"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "b.h5"));
}

}  // namespace
}  // namespace featsense::storage
