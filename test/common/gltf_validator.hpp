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

/// Runs node on test/tools/`script` with `arguments`; its output is stdout and stderr together.
inline ValidatorRun run_node_tool(const std::string& script, const std::string& arguments) {
  const std::string command = "node " + (tools_dir() / script).string() + " " + arguments + " 2>&1";
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

/// Runs the Khronos validator (test/tools/validate_gltf.mjs) on `path`.
inline ValidatorRun run_validator(const std::string& path) {
  return run_node_tool("validate_gltf.mjs", path);
}

/// Checks a tile set (test/tools/check_tileset.mjs: 3D Tiles 1.1's rules, and the Khronos
/// validator on every GLB content unless `gltf` is false); one JSON line comes back.
inline ValidatorRun run_tileset_check(const std::string& tileset_json, bool gltf = true) {
  return run_node_tool("check_tileset.mjs", tileset_json + (gltf ? "" : " --no-gltf"));
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
