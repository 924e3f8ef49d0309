#pragma once
// A one-line progress display on a terminal: items done / total, rate, ETA. Silent when
// quiet or when stderr is not a terminal (logs and CI stay clean).

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "featsense/mapping/run_events.hpp"

namespace featsense::app {

class Progress {
 public:
  /// `what` names the items ("frames"); `total` when known.
  Progress(std::string what, std::optional<size_t> total, bool quiet);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Sets the count of items done and redraws at most a few times per second.
  void update(size_t done, const std::string& extra = "");
  /// Clears the line (called by the destructor too).
  void finish();
  double elapsed_s() const;

 private:
  std::string what_;
  std::optional<size_t> total_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

/// A mapping run's events as the command line shows them: a progress line per pass (a pass
/// that starts again from its first scan gets a new line), messages through the log, and
/// `stop` (a StopSignal's token) as the run's stop token.
mapping::RunEvents terminal_events(const mapping::StopToken& stop, bool quiet);

}  // namespace featsense::app
