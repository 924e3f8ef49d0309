#pragma once
// Ctrl+C and SIGTERM during a long run: the first requests a stop on the run's stop token (the
// run finishes the scans in flight, writes the map and the report); the second exits at once,
// leaving the store as a crash would (readable up to its last flush).

#include "featsense/mapping/stop_token.hpp"

namespace featsense::app {

/// A run that a signal stopped after writing what it had: the program exits with 130.
using Interrupted = mapping::Interrupted;

class StopSignal {
 public:
  /// What a long run says on the first signal.
  static constexpr const char* kMapMessage =
      "finishing the scans in flight and writing the map (press Ctrl+C again to quit at once)";

  /// Installs the handlers for SIGINT and SIGTERM; the destructor restores the old ones. The
  /// first signal prints "featsense: stopping: `message`" (a static string) and requests a
  /// stop on token().
  explicit StopSignal(const char* message = kMapMessage);
  ~StopSignal();
  StopSignal(const StopSignal&) = delete;
  StopSignal& operator=(const StopSignal&) = delete;

  /// The token a signal sets: hand it to the run (RunEvents::stop).
  const mapping::StopToken& token() const { return token_; }
  /// True once SIGINT or SIGTERM arrived.
  bool requested() const { return token_.stop_requested(); }

 private:
  mapping::StopToken token_;
};

}  // namespace featsense::app
