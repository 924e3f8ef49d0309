// The sessions and keyframes a map keeps: they come back as written, are durable at every
// flush like chunks, survive the crashes the journal is made for without duplicates, and stay
// when a map is continued and checkpointed again.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "storage/storage_test_util.hpp"

namespace featsense::storage {
namespace {

using test::journal_of;
using test::make_chunk;
using test::make_keyframe;
using test::make_session;
using test::no_checkpoint;
using test::same_keyframe;
using test::same_session;
using test::test_metadata;

std::vector<StoredKeyframe> keyframes_of(uint32_t session, uint32_t first, uint32_t count) {
  std::vector<StoredKeyframe> keyframes;
  for (uint32_t i = first; i < first + count; ++i) keyframes.push_back(make_keyframe(session, i));
  return keyframes;
}

/// The store holds exactly `expected` (in any order of writing), compared field by field.
void expect_keyframes(const Hdf5ChunkStore& store, std::vector<StoredKeyframe> expected) {
  std::sort(expected.begin(), expected.end(),
            [](const auto& a, const auto& b) { return a.key() < b.key(); });
  const auto stored = store.read_keyframes();
  ASSERT_EQ(stored.size(), expected.size());
  for (std::size_t i = 0; i < stored.size(); ++i)
    EXPECT_TRUE(same_keyframe(stored[i], expected[i]))
        << "keyframe " << expected[i].index << " of session " << expected[i].session;
}

void expect_sessions(const Hdf5ChunkStore& store, const std::vector<MapSession>& expected) {
  const auto stored = store.read_sessions();
  ASSERT_EQ(stored.size(), expected.size());
  for (std::size_t i = 0; i < stored.size(); ++i)
    EXPECT_TRUE(same_session(stored[i], expected[i])) << "session " << expected[i].id;
}

TEST(MapSessions, RoundTripThroughCloseAndReopen) {
  const auto path = test::scratch_dir("sessions_round_trip") / "map.h5";
  auto keyframes = keyframes_of(0, 0, 5);
  // Edge cases: no points, no descriptor, an odd shape, indices past 9 (names sort apart).
  keyframes.push_back(make_keyframe(0, 10, 0));
  StoredKeyframe bare = make_keyframe(2, 3, 7);
  bare.descriptor_rows = 0;
  bare.descriptor_cols = 0;
  bare.descriptor.clear();
  keyframes.push_back(bare);
  StoredKeyframe odd = make_keyframe(2, 4, 1);
  odd.descriptor_rows = 1;
  odd.descriptor_cols = 3;
  odd.descriptor = {-1.0f, 0.5f, std::numeric_limits<float>::max()};
  keyframes.push_back(odd);
  const std::vector<MapSession> sessions = {make_session(0, "first session"),
                                            make_session(2, "relocalized")};
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
    store.write({1, 2, 3}, make_chunk(7));
    store.write_keyframes(keyframes);
    store.write_sessions({sessions[1], sessions[0]});  // kept sorted by id
    expect_keyframes(store, keyframes);                // before any flush
    expect_sessions(store, sessions);
    store.close();
  }
  EXPECT_EQ(std::filesystem::file_size(journal_of(path)), 8u);  // all in the .h5
  Hdf5ChunkStore store(path);
  EXPECT_EQ(store.metadata().format_version, kFormatVersion);
  expect_keyframes(store, keyframes);
  expect_sessions(store, sessions);
  EXPECT_TRUE(*store.read({1, 2, 3}) == make_chunk(7));
  const std::vector<KeyframeKey> keys = store.keyframe_keys();
  ASSERT_EQ(keys.size(), keyframes.size());
  EXPECT_TRUE(keys[5] == (KeyframeKey{0, 10}));
  ASSERT_TRUE(store.read_keyframe({2, 4}).has_value());
  EXPECT_TRUE(same_keyframe(*store.read_keyframe({2, 4}), odd));
  EXPECT_FALSE(store.read_keyframe({2, 5}).has_value());
  EXPECT_FALSE(store.read_keyframe({1, 0}).has_value());
}

TEST(MapSessions, RewritingAKeyReplacesTheKeyframe) {
  const auto path = test::scratch_dir("sessions_replace") / "map.h5";
  StoredKeyframe moved = make_keyframe(0, 1);
  moved.pose.x += 5.0;
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), no_checkpoint());
    store.write_keyframes(keyframes_of(0, 0, 3));
    store.flush();
    store.write_keyframes({moved});
    store.flush();
  }
  Hdf5ChunkStore store(path);
  expect_keyframes(store, {make_keyframe(0, 0), moved, make_keyframe(0, 2)});
}

TEST(MapSessions, DurableAtFlushWithoutClose) {
  const auto path = test::scratch_dir("sessions_flush") / "map.h5";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
    store.write_sessions({make_session(0, "first session")});
    store.write_keyframes(keyframes_of(0, 0, 4));
    store.flush();
    store.write_keyframes(keyframes_of(0, 4, 2));  // never flushed
    store.write_sessions({make_session(0, "changed, never flushed")});
    ::_exit(0);  // no destructor, no checkpoint
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  Hdf5ChunkStore store(path);
  expect_keyframes(store, keyframes_of(0, 0, 4));
  expect_sessions(store, {make_session(0, "first session")});
}

TEST(MapSessions, TornJournalTailDropsOnlyTheLastRecord) {
  const auto path = test::scratch_dir("sessions_torn") / "map.h5";
  std::uintmax_t first_end = 0;
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), no_checkpoint());
    store.write_sessions({make_session(0, "first session")});
    store.write_keyframes(keyframes_of(0, 0, 3));
    store.flush();
    first_end = store.journal_bytes();
    store.write_keyframes({make_keyframe(0, 3)});
    store.flush();
  }
  // Cut the last keyframe's record in the middle, as a crash during its write would.
  const auto size = std::filesystem::file_size(journal_of(path));
  std::filesystem::resize_file(journal_of(path), first_end + (size - first_end) / 2);
  {
    Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata(), no_checkpoint());
    expect_keyframes(store, keyframes_of(0, 0, 3));
    expect_sessions(store, {make_session(0, "first session")});
    // Records appended after the cut must be found again.
    store.write_keyframes({make_keyframe(0, 4)});
    store.flush();
  }
  Hdf5ChunkStore store(path);
  auto expected = keyframes_of(0, 0, 3);
  expected.push_back(make_keyframe(0, 4));
  expect_keyframes(store, expected);
}

TEST(MapSessions, ReplayAfterACheckpointCutBeforeTruncationAddsNoDuplicates) {
  const auto path = test::scratch_dir("sessions_replay_twice") / "map.h5";
  const std::vector<MapSession> sessions = {make_session(0, "first session")};
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), no_checkpoint());
    store.write({0, 0, 0}, make_chunk(1));
    store.write_sessions(sessions);
    store.write_keyframes(keyframes_of(0, 0, 6));
    store.flush();
  }
  // A checkpoint renames the new .h5 into place and then empties the journal: a kill in
  // between leaves the new .h5 and the old journal, whose records it already holds.
  const auto saved = journal_of(path).string() + ".saved";
  std::filesystem::copy_file(journal_of(path), saved);
  { Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata()); }
  EXPECT_EQ(std::filesystem::file_size(journal_of(path)), 8u);
  std::filesystem::copy_file(saved, journal_of(path),
                             std::filesystem::copy_options::overwrite_existing);
  {
    Hdf5ChunkStore store(path);
    expect_keyframes(store, keyframes_of(0, 0, 6));
    expect_sessions(store, sessions);
  }
  // And once that is checkpointed again, the .h5 alone holds each keyframe once.
  { Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata()); }
  EXPECT_EQ(std::filesystem::file_size(journal_of(path)), 8u);
  Hdf5ChunkStore store(path);
  expect_keyframes(store, keyframes_of(0, 0, 6));
  expect_sessions(store, sessions);
  EXPECT_TRUE(*store.read({0, 0, 0}) == make_chunk(1));
}

TEST(MapSessions, ContinuedMapKeepsTheOldSessionsKeyframes) {
  const auto path = test::scratch_dir("sessions_continue") / "map.h5";
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
    store.write({0, 0, 0}, make_chunk(1));
    store.write_sessions({make_session(0, "first session")});
    store.write_keyframes(keyframes_of(0, 0, 4));
  }
  const std::vector<MapSession> both = {make_session(0, "first session"),
                                        make_session(1, "relocalized")};
  {
    Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata());
    expect_sessions(store, {make_session(0, "first session")});
    EXPECT_EQ(store.keyframe_keys().size(), 4u);
    store.write({1, 0, 0}, make_chunk(2));
    store.write_sessions(both);
    store.write_keyframes(keyframes_of(1, 0, 3));
    store.flush();
    store.write_keyframes(keyframes_of(1, 3, 2));
  }
  auto expected = keyframes_of(0, 0, 4);
  for (const auto& keyframe : keyframes_of(1, 0, 5)) expected.push_back(keyframe);
  {
    Hdf5ChunkStore store(path);
    expect_keyframes(store, expected);
    expect_sessions(store, both);
  }
  // A continuation that adds no keyframe copies every one into its checkpoint.
  { Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata()); }
  Hdf5ChunkStore store(path);
  expect_keyframes(store, expected);
  expect_sessions(store, both);
  EXPECT_TRUE(*store.read({0, 0, 0}) == make_chunk(1));
  EXPECT_TRUE(*store.read({1, 0, 0}) == make_chunk(2));
}

TEST(MapSessions, CheckpointsKeepEverything) {
  // A checkpoint after each flush (a run folds its journal once it outgrows both the limit
  // and half the file, Journal.FoldsCostInProportionToWhatWasJournalled; here every time).
  const auto path = test::scratch_dir("sessions_checkpoints") / "map.h5";
  std::vector<StoredKeyframe> expected;
  const StoreSettings settings = no_checkpoint();
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), settings);
    for (uint32_t batch = 0; batch < 4; ++batch) {
      const auto keyframes = keyframes_of(0, 3 * batch, 3);
      expected.insert(expected.end(), keyframes.begin(), keyframes.end());
      store.write({static_cast<int32_t>(batch), 0, 0}, make_chunk(batch));
      store.write_keyframes(keyframes);
      store.write_sessions({make_session(0, "batch " + std::to_string(batch))});
      store.flush();
      store.checkpoint();
      EXPECT_EQ(store.journal_bytes(), 8u);
      expect_keyframes(store, expected);
    }
  }
  // Without the journal, the .h5 alone holds everything.
  std::filesystem::remove(journal_of(path));
  Hdf5ChunkStore store(path);
  expect_keyframes(store, expected);
  expect_sessions(store, {make_session(0, "batch 3")});
  EXPECT_EQ(store.keys().size(), 4u);
}

TEST(MapSessions, NewMapHasNone) {
  const auto path = test::scratch_dir("sessions_none") / "map.h5";
  { Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata()); }
  Hdf5ChunkStore store(path);
  EXPECT_TRUE(store.read_keyframes().empty());
  EXPECT_TRUE(store.keyframe_keys().empty());
  EXPECT_TRUE(store.read_sessions().empty());
}

/// Writing `batch` fails with std::invalid_argument naming the map and `expected`, and
/// stores nothing of the batch.
void expect_rejected(const std::string& name, const std::vector<StoredKeyframe>& batch,
                     const std::string& expected) {
  const auto path = test::scratch_dir("sessions_bad_" + name) / "map.h5";
  Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
  try {
    store.write_keyframes(batch);
    FAIL() << "no error for: " << name;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
  }
  EXPECT_TRUE(store.keyframe_keys().empty());
}

TEST(MapSessions, BadKeyframesAreRejectedWhenWritten) {
  StoredKeyframe short_descriptor = make_keyframe(0, 1);
  short_descriptor.descriptor.pop_back();
  expect_rejected("descriptor", {make_keyframe(0, 0), short_descriptor}, "not 20 x 60");
  StoredKeyframe partial_point = make_keyframe(0, 1);
  partial_point.cloud_cm.push_back(7);
  expect_rejected("cloud", {make_keyframe(0, 0), partial_point}, "not whole x y z points");
  StoredKeyframe nan_pose = make_keyframe(0, 1);
  nan_pose.pose.qz = std::nan("");
  expect_rejected("pose", {make_keyframe(0, 0), nan_pose}, "not finite");
  StoredKeyframe infinite_stamp = make_keyframe(0, 1);
  infinite_stamp.pose.t_s = std::numeric_limits<double>::infinity();
  expect_rejected("stamp", {infinite_stamp}, "not finite");
}

TEST(MapSessions, BadSessionsAreRejectedWhenWritten) {
  const auto path = test::scratch_dir("sessions_bad_table") / "map.h5";
  Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
  EXPECT_THROW(store.write_sessions({make_session(1, "a"), make_session(1, "b")}),
               std::invalid_argument);
  MapSession nan_stamp = make_session(2, "c");
  nan_stamp.last_stamp_s = std::nan("");
  EXPECT_THROW(store.write_sessions({nan_stamp}), std::invalid_argument);
  EXPECT_TRUE(store.read_sessions().empty());
}

TEST(MapSessions, ReadOnlyMapRefusesWrites) {
  const auto path = test::scratch_dir("sessions_read_only") / "map.h5";
  { Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata()); }
  Hdf5ChunkStore store(path);
  EXPECT_THROW(store.write_keyframes({make_keyframe(0, 0)}), std::logic_error);
  EXPECT_THROW(store.write_sessions({make_session(0, "x")}), std::logic_error);
}

}  // namespace
}  // namespace featsense::storage
