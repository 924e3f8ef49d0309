#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

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

}  // namespace featsense::app
