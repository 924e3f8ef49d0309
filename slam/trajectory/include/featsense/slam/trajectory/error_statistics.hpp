#pragma once
/// Summary statistics of a list of errors, with evo's definitions: std is the population
/// standard deviation, median the mean of the two middle values for an even count, sse the sum
/// of squares.

#include <cstddef>
#include <vector>

namespace featsense::slam {

struct ErrorStatistics {
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
  double sse = 0.0;
  size_t count = 0;
};

/// All zero (count 0) for an empty list.
ErrorStatistics error_statistics(std::vector<double> errors);

}  // namespace featsense::slam
