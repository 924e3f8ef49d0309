#pragma once
// When each scan was ready (its source handed it out: for a live sensor, about when its last
// packet came) and how long it then took to reach a stage. Read by the stages' threads.

#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <unordered_map>

namespace featsense::mapping {

class ScanLatency {
 public:
  using Clock = std::chrono::steady_clock;

  /// Scan `sequence` is ready now (a later call for it keeps the first time).
  void ready(uint64_t sequence) {
    const Clock::time_point now = Clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    ready_.emplace(sequence, now);
  }

  /// Milliseconds since scan `sequence` was ready (nullopt where it never was); `done`
  /// forgets it (its last stage, or the scan was dropped).
  std::optional<double> since_ready(uint64_t sequence, bool done = false) {
    const Clock::time_point now = Clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = ready_.find(sequence);
    if (it == ready_.end()) return std::nullopt;
    const double ms = std::chrono::duration<double, std::milli>(now - it->second).count();
    if (done) ready_.erase(it);
    return ms;
  }

 private:
  std::mutex mutex_;
  std::unordered_map<uint64_t, Clock::time_point> ready_;
};

}  // namespace featsense::mapping
