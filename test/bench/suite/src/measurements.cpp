#include "featsense/bench/measurements.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "featsense/slam/trajectory/error_statistics.hpp"

namespace featsense::bench {

TimingSummary summarize_ms(std::vector<double> samples_ms) {
  TimingSummary s;
  s.count = samples_ms.size();
  if (samples_ms.empty()) return s;
  const slam::ErrorStatistics statistics = slam::error_statistics(samples_ms);
  s.median_ms = statistics.median;
  s.max_ms = statistics.max;
  s.mean_ms = statistics.mean;
  // p95 by the nearest-rank method: the smallest sample with 95 % of the samples at or below.
  std::sort(samples_ms.begin(), samples_ms.end());
  const size_t n = samples_ms.size();
  const size_t rank = static_cast<size_t>(std::ceil(0.95 * static_cast<double>(n)));
  s.p95_ms = samples_ms[std::min(n, std::max<size_t>(rank, 1)) - 1];
  return s;
}

nlohmann::json timing_json(const std::vector<double>& samples_ms) {
  const TimingSummary s = summarize_ms(samples_ms);
  return {{"count", s.count},     {"median_ms", s.median_ms},
          {"p95_ms", s.p95_ms},   {"max_ms", s.max_ms},
          {"mean_ms", s.mean_ms}, {"total_s", s.mean_ms * static_cast<double>(s.count) * 1e-3}};
}

nlohmann::json min_median_max(const std::vector<double>& values) {
  const slam::ErrorStatistics statistics = slam::error_statistics(values);
  return {{"min", statistics.min}, {"median", statistics.median}, {"max", statistics.max}};
}

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

double current_rss_mb() {
  // statm: the program's size and its resident part, in pages.
  std::ifstream statm("/proc/self/statm");
  double size_pages = 0.0, resident_pages = 0.0;
  if (!(statm >> size_pages >> resident_pages)) return 0.0;
  return resident_pages * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1048576.0;
}

}  // namespace featsense::bench
