#pragma once
// Runs the featsense program as a user would, for end-to-end tests of the command line.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace featsense::test {

struct CommandResult {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// The featsense executable of this build.
inline std::string featsense_program() {
  return std::string(FEATSENSE_BINARY_DIR) + "/app/featsense";
}

/// Runs `featsense ARGS` through the shell (stdin closed) and collects its output.
inline CommandResult run_featsense(const std::string& args) {
  CommandResult result;
  const std::string command = featsense_program() + " " + args + " 2>&1 </dev/null";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace featsense::test
