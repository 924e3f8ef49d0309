#include "internal/plot_ticks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace featsense::viewer_export {

AxisTicks axis_ticks(double low, double high, int target) {
  if (!std::isfinite(low) || !std::isfinite(high)) low = high = 0.0;
  if (high < low) std::swap(low, high);
  if (high - low < 1e-12) high = low + std::max(1.0, std::abs(low) * 0.1);
  const double rough = (high - low) / std::max(1, target);
  const double power = std::pow(10.0, std::floor(std::log10(rough)));
  double step = power;
  for (const double factor : {1.0, 2.0, 5.0, 10.0}) {
    step = factor * power;
    if (step >= rough) break;
  }
  AxisTicks ticks;
  ticks.step = step;
  // A hair of slack: data on a round number does not get a tick beyond it.
  ticks.low = std::floor(low / step + 1e-9) * step;
  ticks.high = std::ceil(high / step - 1e-9) * step;
  const int count = static_cast<int>(std::lround((ticks.high - ticks.low) / step));
  for (int i = 0; i <= count; ++i) ticks.values.push_back(ticks.low + i * step);
  return ticks;
}

std::string tick_text(double value, double step) {
  const int decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(step) - 1e-9)), 0, 6);
  char text[32];
  if (std::abs(value) >= 1e6) {
    std::snprintf(text, sizeof(text), "%.3g", value);
  } else {
    std::snprintf(text, sizeof(text), "%.*f", decimals,
                  std::abs(value) < step * 1e-6 ? 0.0 : value);
  }
  return text;
}

}  // namespace featsense::viewer_export
