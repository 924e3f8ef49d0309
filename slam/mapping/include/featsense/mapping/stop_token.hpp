#pragma once
// A request to stop a mapping run, owned by whoever started it: a command line maps Ctrl+C
// onto it, a robot's node its shutdown, a test its own timing. The run polls it between
// scans, finishes the scans in flight and writes what it has; it never reads signals itself.

#include <atomic>
#include <memory>
#include <stdexcept>

namespace featsense::mapping {

/// Copies share one flag. request_stop() is a lock-free atomic store, so a signal handler may
/// call it on a token that was made before the handler was installed.
class StopToken {
 public:
  StopToken() : flag_(std::make_shared<std::atomic<bool>>(false)) {}

  void request_stop() const noexcept { flag_->store(true); }
  bool stop_requested() const noexcept { return flag_->load(); }

 private:
  std::shared_ptr<std::atomic<bool>> flag_;
};

/// A run that its stop token stopped after writing what it had (a command line exits with
/// 130 then, as a shell reports a process that SIGINT ended).
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace featsense::mapping
