#pragma once
// What a mapping run tells its caller while it runs: progress, messages and whether to stop.
// The library never prints: the caller decides what reaches a terminal, a log or a robot's
// diagnostics.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "featsense/mapping/stop_token.hpp"

namespace featsense::mapping {

/// Where a pass stands, after each scan it placed or integrated.
struct RunProgress {
  size_t frames_read = 0;              ///< scans the source handed out so far
  size_t frames_mapped = 0;            ///< scans integrated (or, without a map, placed)
  std::optional<size_t> total_frames;  ///< the recording's scans, where known
  bool integrating = true;             ///< false: poses only, nothing integrated
  size_t shifts = 0;                   ///< moves of the local map
  size_t chunks_written = 0;           ///< chunks written to the store
};

enum class LogLevel { kInfo, kWarning };

using ProgressCallback = std::function<void(const RunProgress&)>;
using LogCallback = std::function<void(LogLevel, const std::string&)>;

/// The caller's side of a run. Callbacks are called from the run's threads (one at a time for
/// progress: the mapping thread's), so they must be thread-safe where they share state.
struct RunEvents {
  StopToken stop;
  ProgressCallback progress;  ///< may be empty
  LogCallback log;            ///< may be empty

  void info(const std::string& text) const {
    if (log) log(LogLevel::kInfo, text);
  }
  void warn(const std::string& text) const {
    if (log) log(LogLevel::kWarning, text);
  }
};

}  // namespace featsense::mapping
