#pragma once
// Per-stage timings in milliseconds and their summary (median / p95 / max), as every
// benchmark and every run's report gives them, and the process's peak memory.

#include <nlohmann/json.hpp>

#include <cstddef>
#include <vector>

namespace featsense::bench {

struct TimingSummary {
  size_t count = 0;
  double median_ms = 0.0;
  double p95_ms = 0.0;
  double max_ms = 0.0;
  double mean_ms = 0.0;
};

/// Summary of samples in milliseconds (p95 by the nearest-rank method).
TimingSummary summarize_ms(std::vector<double> samples_ms);

/// The summary as reports print it: count, median_ms, p95_ms, max_ms, mean_ms, total_s.
nlohmann::json timing_json(const std::vector<double>& samples_ms);

/// {"min", "median", "max"} of the values (all 0 when empty).
nlohmann::json min_median_max(const std::vector<double>& values);

/// The process's peak resident memory so far, MiB.
double peak_rss_mb();

/// The process's resident memory now, MiB (0 where /proc cannot tell).
double current_rss_mb();

}  // namespace featsense::bench
