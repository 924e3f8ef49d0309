#pragma once
// The Khronos glTF validator (test/tools/validate_gltf.mjs, installed by npm in test/tools by
// scripts/test.sh), for the tests of every file that holds glTF: where it is not installed,
// expect_valid checks nothing and GltfValidator.RejectsABrokenFile says so by skipping.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace featsense::test {

inline std::filesystem::path tools_dir() {
  return std::filesystem::path(FEATSENSE_SOURCE_DIR) / "test" / "tools";
}

/// Whether node and the validator (npm install in test/tools) are present.
inline bool validator_present() {
  return std::system("command -v node >/dev/null 2>&1") == 0 &&
         std::filesystem::exists(tools_dir() / "node_modules" / "gltf-validator");
}

struct ValidatorRun {
  int status = -1;     ///< the exit status: 0 without errors
  std::string output;  ///< one JSON report per file
};

/// Runs the Khronos validator (test/tools/validate_gltf.mjs) on `path`.
inline ValidatorRun run_validator(const std::string& path) {
  const std::string command =
      "node " + (tools_dir() / "validate_gltf.mjs").string() + " " + path + " 2>&1";
  ValidatorRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  size_t n = 0;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) run.output.append(buffer, n);
  const int status = pclose(pipe);
  run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

/// Runs the Khronos validator on `path` where it is installed (GltfValidator.RejectsABrokenFile
/// says, by skipping, where it is not); the other checks of a test run either way.
inline void expect_valid(const std::string& path) {
  if (!validator_present()) return;
  const ValidatorRun run = run_validator(path);
  EXPECT_EQ(run.status, 0) << run.output;
  const nlohmann::json report = nlohmann::json::parse(run.output);
  EXPECT_EQ(report["errors"], 0) << run.output;
}

}  // namespace featsense::test
