// The journal beside the .h5: what a crash leaves behind must open with every flushed chunk.

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <fstream>

#include "common/test_data.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "storage/storage_test_util.hpp"

namespace featsense::storage {
namespace {

using test::journal_of;
using test::make_chunk;
using test::no_checkpoint;
using test::test_metadata;

TEST(Journal, FlushedChunksSurviveWithoutCheckpoint) {
  const auto path = test::scratch_dir("journal_replay") / "map.h5";
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), no_checkpoint());
    store.write({3, -4, 5}, make_chunk(1));
    store.write({-3, 4, -5}, make_chunk(2));
    store.flush();
  }
  EXPECT_GT(std::filesystem::file_size(journal_of(path)), 8u);
  Hdf5ChunkStore store(path);
  EXPECT_EQ(store.keys().size(), 2u);
  EXPECT_TRUE(*store.read({3, -4, 5}) == make_chunk(1));
  EXPECT_TRUE(*store.read({-3, 4, -5}) == make_chunk(2));
}

TEST(Journal, ProcessDyingWithoutCleanupKeepsFlushedChunks) {
  const auto path = test::scratch_dir("journal_exit") / "map.h5";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata());
    store.write({0, 0, 0}, make_chunk(1));
    store.flush();
    store.write({1, 1, 1}, make_chunk(2));  // never flushed
    ::_exit(0);                             // no destructor, no checkpoint
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  Hdf5ChunkStore store(path);
  ASSERT_TRUE(store.read({0, 0, 0}).has_value());
  EXPECT_TRUE(*store.read({0, 0, 0}) == make_chunk(1));
  EXPECT_FALSE(store.read({1, 1, 1}).has_value());
}

/// Two flushed chunks in the journal, the second then damaged by `damage(journal, size)`.
void check_damaged_last_record(const std::string& name,
                               void (*damage)(const std::filesystem::path&, std::uintmax_t)) {
  const auto path = test::scratch_dir(name) / "map.h5";
  std::uintmax_t first_end = 0;
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), no_checkpoint());
    store.write({1, 0, 0}, make_chunk(1));
    store.flush();
    first_end = store.journal_bytes();
    store.write({2, 0, 0}, make_chunk(2));
    store.flush();
  }
  damage(journal_of(path), first_end);
  {
    Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata(), no_checkpoint());
    EXPECT_TRUE(*store.read({1, 0, 0}) == make_chunk(1));
    EXPECT_FALSE(store.read({2, 0, 0}).has_value());
    // Records appended after the cut must be found again.
    store.write({3, 0, 0}, make_chunk(3));
    store.flush();
  }
  Hdf5ChunkStore store(path);
  EXPECT_EQ(store.keys().size(), 2u);
  EXPECT_TRUE(*store.read({1, 0, 0}) == make_chunk(1));
  EXPECT_TRUE(*store.read({3, 0, 0}) == make_chunk(3));
}

TEST(Journal, TornLastRecordIsIgnored) {
  check_damaged_last_record(
      "journal_torn", [](const std::filesystem::path& journal, std::uintmax_t first_end) {
        // Cut the second record in the middle, as a crash during its write would.
        const auto size = std::filesystem::file_size(journal);
        std::filesystem::resize_file(journal, first_end + (size - first_end) / 2);
      });
}

TEST(Journal, CorruptLastRecordIsIgnored) {
  check_damaged_last_record(
      "journal_corrupt", [](const std::filesystem::path& journal, std::uintmax_t first_end) {
        // Full length, but one payload byte differs: only the CRC can tell.
        std::fstream file(journal, std::ios::in | std::ios::out | std::ios::binary);
        file.seekg(static_cast<std::streamoff>(first_end + 40));
        char byte = 0;
        file.read(&byte, 1);
        byte = static_cast<char>(byte ^ 0x5A);
        file.seekp(static_cast<std::streamoff>(first_end + 40));
        file.write(&byte, 1);
      });
}

TEST(Journal, GrowingPastItsLimitFoldsIntoTheH5) {
  const auto path = test::scratch_dir("journal_limit") / "map.h5";
  StoreSettings settings = no_checkpoint();
  settings.journal_limit_bytes = 1u << 20;
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), settings);
    for (uint32_t i = 0; i < 12; ++i) {
      store.write({static_cast<int32_t>(i), -1, 0}, make_chunk(i));
      store.flush();
      EXPECT_LE(store.journal_bytes(), settings.journal_limit_bytes);
    }
  }
  // Without the journal, the .h5 alone holds every chunk up to the last checkpoint.
  const auto journal_size = std::filesystem::file_size(journal_of(path));
  std::filesystem::remove(journal_of(path));
  Hdf5ChunkStore store(path);
  EXPECT_GE(store.keys().size(), 12u - journal_size / 100000);  // records are > 100 kB here
  for (const auto& key : store.keys())
    EXPECT_TRUE(*store.read(key) == make_chunk(static_cast<uint32_t>(key.x)));
}

TEST(Journal, FoldsCostInProportionToWhatWasJournalled) {
  // Each fold rewrites the whole .h5. With a fixed journal limit a map of n chunks written one
  // by one was rewritten about n times (n^2 / 2 chunks copied); folding only once the journal
  // is also half the file copies each journalled chunk a bounded number of times.
  const auto path = test::scratch_dir("journal_amortized") / "map.h5";
  StoreSettings settings = no_checkpoint();
  settings.journal_limit_bytes = 64u << 10;
  constexpr uint32_t kChunks = 40;
  Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), settings);
  std::uintmax_t rewritten = 0, last_size = std::filesystem::file_size(path);
  int folds = 0;
  for (uint32_t i = 0; i < kChunks; ++i) {
    store.write({static_cast<int32_t>(i), 0, 0}, make_chunk(i));
    store.flush();
    const std::uintmax_t size = std::filesystem::file_size(path);
    if (size != last_size) {  // only a fold writes the .h5
      ++folds;
      rewritten += size;
    } else {
      EXPECT_LE(store.journal_bytes(),
                std::max<std::uintmax_t>(settings.journal_limit_bytes, last_size / 2));
    }
    last_size = size;
  }
  // Every chunk is about 1 MB stored, so each write passes the fixed limit: 40 folds and 820
  // chunks rewritten before; now 7 folds (at 1, 2, 4, 7, 11, 17 and 26 chunks), 68 rewritten.
  EXPECT_GT(last_size, kChunks * 100000u);
  EXPECT_LE(folds, 10);
  EXPECT_LE(rewritten, 3 * last_size);
  for (uint32_t i = 0; i < kChunks; i += 7)
    EXPECT_TRUE(*store.read({static_cast<int32_t>(i), 0, 0}) == make_chunk(i));
}

TEST(Journal, ForeignJournalIsAnError) {
  const auto path = test::scratch_dir("journal_foreign") / "map.h5";
  { Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata()); }
  { std::ofstream(journal_of(path)) << "something else entirely"; }
  try {
    Hdf5ChunkStore store(path);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(journal_of(path).string()), std::string::npos);
  }
}

TEST(Journal, FullDiskGivesAClearErrorAndKeepsEarlierChunks) {
  const auto path = test::scratch_dir("journal_full") / "map.h5";
  {
    Hdf5ChunkStore store(path, OpenMode::kCreate, test_metadata(), no_checkpoint());
    store.write({0, 0, 0}, make_chunk(1));
    store.flush();
  }
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // A file size limit makes write() fail with EFBIG, as a full disk fails with ENOSPC.
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{std::filesystem::file_size(journal_of(path)) + 1000,
                       std::filesystem::file_size(journal_of(path)) + 1000};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    int code = 1;
    try {
      Hdf5ChunkStore store(path, OpenMode::kAppend, test_metadata(), no_checkpoint());
      store.write({1, 0, 0}, make_chunk(2));
      store.flush();
    } catch (const std::runtime_error& e) {
      code = std::string(e.what()).find(journal_of(path).string()) != std::string::npos ? 0 : 2;
    }
    ::_exit(code);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: no error, 2: the error did not name the journal";
  Hdf5ChunkStore store(path);
  EXPECT_TRUE(*store.read({0, 0, 0}) == make_chunk(1));
  EXPECT_FALSE(store.read({1, 0, 0}).has_value());
}

}  // namespace
}  // namespace featsense::storage
