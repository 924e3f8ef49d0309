#pragma once
// Medians and a robust variance, for weighing one sensor against another by how they agree:
// a jolt or two among the errors must not count.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace featsense::slam::loops {

/// The median of chi^2 with one degree of freedom.
constexpr double kMedianChiSquared1 = 0.4549;

/// The element at size / 2 in order (the upper median), reordering `values` (not empty).
inline double upper_median(std::vector<double>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/// The variance of normal errors from their squares (`squares`, not empty, reordered): their
/// upper median over the median of chi^2 with one degree of freedom.
inline double robust_variance(std::vector<double>& squares) {
  return upper_median(squares) / kMedianChiSquared1;
}

}  // namespace featsense::slam::loops
