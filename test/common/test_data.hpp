#pragma once
// Where the tests find the shared sensor recordings (../shared/data beside the checkout),
// and a skip for machines that do not have them.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace featsense::test {

/// ../shared/data relative to the project root, or an empty path when it is absent.
inline std::filesystem::path shared_data_dir() {
  const std::filesystem::path dir =
      std::filesystem::path(FEATSENSE_SOURCE_DIR).parent_path() / "shared" / "data";
  return std::filesystem::is_directory(dir) ? dir : std::filesystem::path();
}

/// This process's scratch folders, removed when it exits normally (a run of the suite
/// writes maps and recordings of several GB; kept after a crash, for a look). Set
/// FEATSENSE_KEEP_TEST_FILES to keep them always.
class ProcessScratch {
 public:
  ProcessScratch()
      : pid_(::getpid()),
        root_(std::filesystem::temp_directory_path() / "featsense-test" / std::to_string(pid_)) {}
  ProcessScratch(const ProcessScratch&) = delete;
  ProcessScratch& operator=(const ProcessScratch&) = delete;
  ~ProcessScratch() {
    // A forked child that exits normally must not remove its parent's files.
    if (::getpid() != pid_ || std::getenv("FEATSENSE_KEEP_TEST_FILES") != nullptr) return;
    std::error_code ignored;
    std::filesystem::remove_all(root_, ignored);
  }
  const std::filesystem::path& root() const { return root_; }

 private:
  pid_t pid_;
  std::filesystem::path root_;
};

/// A scratch folder for one test, emptied first.
inline std::filesystem::path scratch_dir(const std::string& name) {
  // Per process: ctest runs test programs, and the instances of a parameterised test, in
  // parallel, and two of them must never empty each other's folder.
  static const ProcessScratch process;
  const std::filesystem::path dir = process.root() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace featsense::test

/// Skips the test (with a message) where ../shared/data/<relative> does not exist, else sets
/// `var` to its full path.
#define FEATSENSE_SHARED_FILE(var, relative)                                               \
  const std::filesystem::path var = ::featsense::test::shared_data_dir() / (relative);     \
  if (::featsense::test::shared_data_dir().empty() || !std::filesystem::exists(var)) {     \
    GTEST_SKIP() << "shared recording " << (relative) << " not found beside the checkout"; \
  }
