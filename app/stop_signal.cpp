#include "stop_signal.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>

namespace featsense::app {
namespace {

std::atomic<int> g_signals{0};
// Set before the handlers are installed, read in the handler.
const char* g_message = "";
std::size_t g_message_length = 0;
const mapping::StopToken* g_token = nullptr;
struct sigaction g_old_int {};
struct sigaction g_old_term {};

extern "C" void on_stop_signal(int) {
  // Only async-signal-safe calls here: atomics (the token's is lock-free), write(2), _exit(2).
  if (g_signals.fetch_add(1) == 0) {
    if (g_token) g_token->request_stop();
    static const char kFirst[] = "\nfeatsense: stopping: ";
    [[maybe_unused]] ssize_t n = ::write(STDERR_FILENO, kFirst, sizeof(kFirst) - 1);
    n = ::write(STDERR_FILENO, g_message, g_message_length);
    n = ::write(STDERR_FILENO, "\n", 1);
    return;
  }
  static const char kSecond[] = "\nfeatsense: quit; the map holds what was flushed before\n";
  [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, kSecond, sizeof(kSecond) - 1);
  ::_exit(130);
}

}  // namespace

StopSignal::StopSignal(const char* message) {
  static_assert(std::atomic<bool>::is_always_lock_free, "the stop flag is set in a handler");
  g_signals.store(0);
  g_message = message;
  g_message_length = std::strlen(message);
  g_token = &token_;
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, &g_old_int);
  sigaction(SIGTERM, &action, &g_old_term);
}

StopSignal::~StopSignal() {
  sigaction(SIGINT, &g_old_int, nullptr);
  sigaction(SIGTERM, &g_old_term, nullptr);
  g_token = nullptr;
}

}  // namespace featsense::app
