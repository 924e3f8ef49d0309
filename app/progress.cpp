#include "progress.hpp"

#include <unistd.h>

#include <spdlog/spdlog.h>

#include <cstdio>
#include <mutex>

namespace featsense::app {

Progress::Progress(std::string what, std::optional<size_t> total, bool quiet)
    : what_(std::move(what)),
      total_(total),
      enabled_(!quiet && isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() { finish(); }

double Progress::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::update(size_t done, const std::string& extra) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && now - last_draw_ < std::chrono::milliseconds(200)) return;
  last_draw_ = now;
  drawn_ = true;
  const double elapsed = elapsed_s();
  const double rate = elapsed > 0.0 ? static_cast<double>(done) / elapsed : 0.0;
  std::string line = std::to_string(done);
  if (total_) line += " / " + std::to_string(*total_);
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, " %s, %.1f/s", what_.c_str(), rate);
  line += buffer;
  if (total_ && rate > 0.0 && *total_ >= done) {
    std::snprintf(buffer, sizeof buffer, ", ETA %.0f s",
                  static_cast<double>(*total_ - done) / rate);
    line += buffer;
  }
  if (!extra.empty()) line += ", " + extra;
  std::fprintf(stderr, "\r\033[K%s", line.c_str());
  std::fflush(stderr);
}

void Progress::finish() {
  if (enabled_ && drawn_) {
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
    drawn_ = false;
  }
}

namespace {

/// The progress lines of a run's passes: the callbacks come from one thread at a time.
class PassProgress {
 public:
  explicit PassProgress(bool quiet) : quiet_(quiet) {}

  void update(const mapping::RunProgress& at) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!line_ || at.frames_read < last_read_)
      line_ = std::make_unique<Progress>("frames", at.total_frames, quiet_);
    last_read_ = at.frames_read;
    char text[96];
    if (at.integrating) {
      std::snprintf(text, sizeof(text), "%zu mapped, %zu shifts, %zu chunks written",
                    at.frames_mapped, at.shifts, at.chunks_written);
    } else {
      std::snprintf(text, sizeof(text), "%zu placed", at.frames_mapped);
    }
    line_->update(at.frames_read, text);
  }

 private:
  bool quiet_;
  std::mutex mutex_;
  std::unique_ptr<Progress> line_;
  size_t last_read_ = 0;
};

}  // namespace

mapping::RunEvents terminal_events(const mapping::StopToken& stop, bool quiet) {
  mapping::RunEvents events;
  events.stop = stop;
  auto progress = std::make_shared<PassProgress>(quiet);
  events.progress = [progress](const mapping::RunProgress& at) { progress->update(at); };
  events.log = [](mapping::LogLevel level, const std::string& text) {
    if (level == mapping::LogLevel::kWarning) {
      spdlog::warn("{}", text);
    } else {
      spdlog::info("{}", text);
    }
  };
  return events;
}

}  // namespace featsense::app
