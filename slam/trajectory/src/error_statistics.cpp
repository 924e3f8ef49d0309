#include "featsense/slam/trajectory/error_statistics.hpp"

#include <algorithm>
#include <cmath>

namespace featsense::slam {

ErrorStatistics error_statistics(std::vector<double> errors) {
  ErrorStatistics s;
  if (errors.empty()) return s;
  s.count = errors.size();
  const double n = static_cast<double>(errors.size());
  double sum = 0.0;
  for (double e : errors) {
    sum += e;
    s.sse += e * e;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(s.sse / n);
  double squared_deviation = 0.0;
  for (double e : errors) squared_deviation += (e - s.mean) * (e - s.mean);
  s.std = std::sqrt(squared_deviation / n);
  std::sort(errors.begin(), errors.end());
  s.min = errors.front();
  s.max = errors.back();
  const size_t half = errors.size() / 2;
  s.median = errors.size() % 2 == 1 ? errors[half] : 0.5 * (errors[half - 1] + errors[half]);
  return s;
}

}  // namespace featsense::slam
