#pragma once
/// Sending a pcap's UDP payloads to a host as the sensor sent them: on their recorded ports
/// (or others), with their recorded timing (or faster, slower), once or in a loop, with a
/// share dropped on purpose. For dry runs of live input (`featsense live`) and its tests.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>

namespace featsense::slam {

struct ReplaySettings {
  std::string host = "127.0.0.1";  ///< IPv4 address sent to
  double rate = 1.0;               ///< speed against the recording (2: twice as fast), > 0
  bool loop = false;               ///< start over at the end, until stopped
  double drop_fraction = 0.0;      ///< drop this share of the datagrams at random, [0, 1)
  uint64_t seed = 1;               ///< of the drops: the same seed drops the same datagrams
  std::map<int, int> ports;        ///< recorded port -> port sent to (others unchanged)
  /// Polled between datagrams: true ends the replay.
  std::function<bool()> stop_requested;
  /// Called about every 0.2 s of sending, with the datagrams sent so far.
  std::function<void(size_t sent)> progress;
};

struct ReplayResult {
  size_t sent = 0;
  size_t dropped = 0;    ///< on purpose (drop_fraction)
  size_t failed = 0;     ///< sendto errors (a full socket buffer, no route)
  size_t bytes = 0;      ///< payload bytes sent
  size_t passes = 0;     ///< times the capture was sent through (a stop may end the last early)
  double seconds = 0.0;  ///< wall time spent
  double recording_seconds = 0.0;  ///< the span of one pass's timestamps
};

/// Replays `path`. Throws InputError where it cannot be read or `settings` are out of range.
ReplayResult replay_pcap(const std::string& path, const ReplaySettings& settings);

}  // namespace featsense::slam
