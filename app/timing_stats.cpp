#include "timing_stats.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace featsense::app {

TimingSummary summarize_ms(std::vector<double> samples_ms) {
  TimingSummary s;
  s.count = samples_ms.size();
  if (samples_ms.empty()) return s;
  std::sort(samples_ms.begin(), samples_ms.end());
  const size_t n = samples_ms.size();
  s.median_ms = n % 2 == 1 ? samples_ms[n / 2] : 0.5 * (samples_ms[n / 2 - 1] + samples_ms[n / 2]);
  const size_t rank = static_cast<size_t>(std::ceil(0.95 * static_cast<double>(n)));
  s.p95_ms = samples_ms[std::min(n, std::max<size_t>(rank, 1)) - 1];
  s.max_ms = samples_ms.back();
  s.mean_ms = std::accumulate(samples_ms.begin(), samples_ms.end(), 0.0) / static_cast<double>(n);
  return s;
}

nlohmann::json to_json(const TimingSummary& s) {
  return {{"count", s.count},
          {"median_ms", s.median_ms},
          {"p95_ms", s.p95_ms},
          {"max_ms", s.max_ms},
          {"mean_ms", s.mean_ms}};
}

}  // namespace featsense::app
