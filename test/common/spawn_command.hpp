#pragma once
// Runs the featsense program in the background, for tests that stop it with a signal.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "common/run_command.hpp"

namespace featsense::test {

/// The text of a file (empty where it cannot be read): a child's log.
inline std::string text_of(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Waits for the child to end; its exit status (-1 where a signal ended it).
inline int wait_exit_code(pid_t child) {
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

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

/// Waits until `log` contains `what` (false: the child ended first, or 30 s passed).
inline bool wait_for_line(const std::filesystem::path& log, const std::string& what, pid_t child) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < end) {
    if (text_of(log).find(what) != std::string::npos) return true;
    int status = 0;
    if (waitpid(child, &status, WNOHANG) == child) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
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

/// Waits for the child's first flush (wait_for_first_flush), then kills it with SIGKILL and
/// reaps it, whether the flush came or not (a child left running would outlive the test).
/// Fails where the child ended before its first flush or was not ended by the kill.
inline ::testing::AssertionResult killed_after_first_flush(
    const std::filesystem::path& journal, pid_t child,
    std::chrono::seconds timeout = std::chrono::seconds(30)) {
  const bool flushed = wait_for_first_flush(journal, child, timeout);
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  if (!flushed) return ::testing::AssertionFailure() << "the run ended before its first flush";
  if (!WIFSIGNALED(status)) return ::testing::AssertionFailure() << "the kill did not end the run";
  return ::testing::AssertionSuccess();
}

}  // namespace featsense::test
