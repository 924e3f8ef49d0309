#pragma once
// Medians and a robust variance, for weighing one sensor against another by how they agree:
// a jolt or two among the errors must not count.

#include <vector>

#include "featsense/slam/upper_median.hpp"

namespace featsense::slam::loops {

/// The median of chi^2 with one degree of freedom.
constexpr double kMedianChiSquared1 = 0.4549;

/// The variance of normal errors from their squares (`squares`, not empty, reordered): their
/// upper median over the median of chi^2 with one degree of freedom.
inline double robust_variance(std::vector<double>& squares) {
  return upper_median(squares) / kMedianChiSquared1;
}

}  // namespace featsense::slam::loops
