#pragma once
// Ctrl+C and SIGTERM during a long run: the first asks the run to stop (it finishes the
// scans in flight, writes the map and the report); the second exits at once, leaving the
// store as a crash would (readable up to its last flush).

#include <stdexcept>

namespace featsense::app {

/// A run that a signal stopped after writing what it had: the program exits with 130, as a
/// shell reports a process that SIGINT ended.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class StopSignal {
 public:
  /// What a long run says on the first signal.
  static constexpr const char* kMapMessage =
      "finishing the scans in flight and writing the map (press Ctrl+C again to quit at once)";

  /// Installs the handlers for SIGINT and SIGTERM; the destructor restores the old ones. The
  /// first signal prints "featsense: stopping: `message`" (a static string).
  explicit StopSignal(const char* message = kMapMessage);
  ~StopSignal();
  StopSignal(const StopSignal&) = delete;
  StopSignal& operator=(const StopSignal&) = delete;

  /// True once SIGINT or SIGTERM arrived.
  static bool requested();
};

}  // namespace featsense::app
