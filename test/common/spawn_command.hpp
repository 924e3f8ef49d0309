#pragma once
// Runs the featsense program in the background, for tests that stop it with a signal.

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

#include "common/run_command.hpp"

namespace featsense::test {

/// Starts `featsense ARGS` as a child process, its output into `log`; returns its pid.
inline pid_t spawn_featsense(const std::string& args, const std::filesystem::path& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string command =
        "exec " + featsense_program() + " " + args + " >" + log.string() + " 2>&1 </dev/null";
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

/// Waits until the store's journal holds a flushed chunk (false: the child ended first, or
/// `timeout` passed).
inline bool wait_for_first_flush(const std::filesystem::path& journal, pid_t child,
                                 std::chrono::seconds timeout = std::chrono::seconds(30)) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (std::filesystem::exists(journal) && std::filesystem::file_size(journal) > 4096) return true;
    int status = 0;
    if (waitpid(child, &status, WNOHANG) == child) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

}  // namespace featsense::test
