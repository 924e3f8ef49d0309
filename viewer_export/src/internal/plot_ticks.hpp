#pragma once
// Where an axis puts its tick marks: round numbers (1, 2 or 5 times a power of ten), so that
// the labels read at a glance.

#include <string>
#include <vector>

namespace featsense::viewer_export {

struct AxisTicks {
  double low = 0.0;   ///< the axis starts here (a tick, at or below the data)
  double high = 1.0;  ///< and ends here (a tick, at or above the data)
  double step = 0.1;
  std::vector<double> values;  ///< low, low + step, ..., high
};

/// About `target` ticks spanning [low, high]; an empty or reversed range is widened.
AxisTicks axis_ticks(double low, double high, int target);

/// A tick's label, with as many decimals as `step` needs ("0.25", "10", "1e+03").
std::string tick_text(double value, double step);

}  // namespace featsense::viewer_export
