// A real crash: a child process writes and flushes chunks and keyframes in a loop, reporting
// each flushed step through a pipe, and is killed with SIGKILL mid-run (also during
// checkpoints, which a small journal limit makes frequent). Every reported chunk and keyframe
// must be in the reopened map.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "storage/storage_test_util.hpp"

namespace featsense::storage {
namespace {

using test::make_chunk;
using test::make_keyframe;
using test::same_keyframe;
using test::test_metadata;

/// The i-th key the child writes, spread over negative and positive coordinates.
ChunkKey key_of(int32_t i) { return {i % 5 - 2, (i / 5) % 5 - 2, i / 25 - 2}; }

StoreSettings child_settings(std::size_t journal_limit_bytes) {
  StoreSettings settings;
  settings.cache_bytes = 3 * kChunkBytes;
  settings.journal_limit_bytes = journal_limit_bytes;
  return settings;
}

[[noreturn]] void run_child(const std::filesystem::path& path, std::size_t journal_limit_bytes,
                            int report_fd) {
  try {
    Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata(),
                         child_settings(journal_limit_bytes));
    for (int32_t i = 0; i < 100000; ++i) {
      store.write(key_of(i), make_chunk(static_cast<uint32_t>(i)));
      store.write_keyframes({make_keyframe(0, static_cast<uint32_t>(i), 500)});
      store.flush();
      if (::write(report_fd, &i, sizeof(i)) != sizeof(i)) ::_exit(3);
    }
  } catch (...) {
    ::_exit(2);
  }
  ::_exit(0);
}

/// Starts the child, kills it `delay_us` after its `reports`-th flushed key, returns every
/// key it reported.
std::set<int32_t> crash_after(const std::filesystem::path& path, std::size_t journal_limit_bytes,
                              int reports, int delay_us) {
  int fds[2];
  if (::pipe(fds) != 0) return {};
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(fds[0]);
    run_child(path, journal_limit_bytes, fds[1]);
  }
  ::close(fds[1]);
  std::set<int32_t> reported;
  int32_t i = 0;
  while (static_cast<int>(reported.size()) < reports && ::read(fds[0], &i, sizeof(i)) == sizeof(i))
    reported.insert(i);
  // Without a delay the kill would always land just after a report, at the same step.
  ::usleep(static_cast<useconds_t>(delay_us));
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status)) << "the child ended by itself, status " << status;
  // Reports already in the pipe were flushed before the kill too.
  while (::read(fds[0], &i, sizeof(i)) == sizeof(i)) reported.insert(i);
  ::close(fds[0]);
  return reported;
}

void check_crash(const std::string& name, std::size_t journal_limit_bytes, int reports,
                 int delay_us) {
  const auto path = test::scratch_dir(name + "_" + std::to_string(reports)) / "map.h5";
  { Hdf5ChunkStore create(path, OpenMode::kCreate, test_metadata()); }
  const std::set<int32_t> reported = crash_after(path, journal_limit_bytes, reports, delay_us);
  ASSERT_GE(static_cast<int>(reported.size()), reports);

  Hdf5ChunkStore store(path);
  for (const int32_t i : reported) {
    const auto chunk = store.read(key_of(i));
    ASSERT_TRUE(chunk.has_value()) << "flushed chunk " << i << " lost";
    EXPECT_TRUE(*chunk == make_chunk(static_cast<uint32_t>(i))) << "chunk " << i;
  }
  // At most the one chunk flushed but not yet reported may be there besides.
  EXPECT_LE(store.keys().size(), reported.size() + 1);
  for (const auto& key : store.keys()) {
    const int32_t i = (key.x + 2) + 5 * (key.y + 2) + 25 * (key.z + 2);
    EXPECT_TRUE(*store.read(key) == make_chunk(static_cast<uint32_t>(i))) << "chunk " << i;
  }
  // The keyframe of each step was flushed with its chunk.
  const std::vector<StoredKeyframe> keyframes = store.read_keyframes();
  std::set<int32_t> stored;
  for (const StoredKeyframe& keyframe : keyframes) {
    stored.insert(static_cast<int32_t>(keyframe.index));
    EXPECT_TRUE(same_keyframe(keyframe, make_keyframe(0, keyframe.index, 500)))
        << "keyframe " << keyframe.index;
  }
  for (const int32_t i : reported)
    EXPECT_EQ(stored.count(i), 1u) << "flushed keyframe " << i << " lost";
  EXPECT_LE(keyframes.size(), reported.size() + 1);
}

TEST(CrashKill, EveryReportedChunkSurvivesSigkill) {
  // A checkpoint every dozen flushes or so: the kill mostly lands in a journal append.
  for (const auto& [reports, delay_us] : {std::pair{3, 0}, {11, 2000}, {29, 7000}})
    check_crash("crash_kill", 4u << 20, reports, delay_us);
}

TEST(CrashKill, KillDuringCheckpointsLosesNothing) {
  // A checkpoint after every flush: the kill mostly lands while a new .h5 is written or
  // renamed into place.
  for (const auto& [reports, delay_us] : {std::pair{2, 5000}, {7, 20000}, {15, 40000}})
    check_crash("crash_kill_checkpoint", 1, reports, delay_us);
}

}  // namespace
}  // namespace featsense::storage
