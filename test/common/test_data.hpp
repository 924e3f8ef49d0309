#pragma once
// Where the tests find the shared sensor recordings (../shared/data beside the checkout),
// and a skip for machines that do not have them.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace featsense::test {

/// ../shared/data relative to the project root, or an empty path when it is absent.
inline std::filesystem::path shared_data_dir() {
  const std::filesystem::path dir =
      std::filesystem::path(FEATSENSE_SOURCE_DIR).parent_path() / "shared" / "data";
  return std::filesystem::is_directory(dir) ? dir : std::filesystem::path();
}

/// A scratch folder for one test, emptied first.
inline std::filesystem::path scratch_dir(const std::string& name) {
  // Per process: ctest runs test programs, and the instances of a parameterised test, in
  // parallel, and two of them must never empty each other's folder.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "featsense-test" / std::to_string(::getpid()) / name;
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
