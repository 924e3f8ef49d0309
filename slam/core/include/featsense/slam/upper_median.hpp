#pragma once
// The median the front end, the readers and the loops take of their samples: the element at
// half the count in order, found by a partial sort (the upper one of an even count's two middle
// values, itself a sample, never an average of two).

#include <algorithm>
#include <cstddef>
#include <vector>

namespace featsense::slam {

/// The element at size / 2 in order, reordering `values` (which must not be empty).
template <typename T>
T upper_median(std::vector<T>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace featsense::slam
