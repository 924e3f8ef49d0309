#pragma once
// The accuracy figures of a comparison gathered a distance at a time, in memory that does not
// grow with the points, so that a city's mesh is compared without holding its distances:
// sums for the means, deviations and RMSE, exact counts for max_dist and the thresholds, the
// exact maximum, and the median and p95 from a histogram of |d| whose bins are 1/32768 of an
// octave (a float's exponent and its 15 leading mantissa bits), a bin's values standing for
// themselves by their mean: within 0.003 % of the exact order statistic, and exact where a
// bin holds one value.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "featsense/mesh/compare_to_reference.hpp"

namespace featsense::mesh::internal {

class DistanceAccumulator {
 public:
  explicit DistanceAccumulator(const CompareSettings& settings);

  /// One estimate point: its distance and its signed one (equal where there is no sign).
  void add(float unsigned_m, float signed_m);

  /// Points, beyond_max_dist, accuracy (over the points within max_dist) and the histogram.
  void fill(CompareResult* result) const;

  /// Per threshold of the settings, the points within it (all points, max_dist or not).
  const std::vector<size_t>& within() const { return within_; }

 private:
  struct Bin {
    uint64_t count = 0;
    double sum = 0.0;
  };
  static constexpr int kMantissaBits = 15;
  static constexpr int kOctaves = 37;  ///< 2^-20 m (1 micrometre) to 2^17 m
  static constexpr size_t kBinsPerOctave = size_t{1} << kMantissaBits;

  Bin& bin_of(float magnitude);
  /// The value of rank `rank` (0-based) among the kept magnitudes, by its bin's mean.
  double ranked(uint64_t rank) const;

  double max_dist_m_;
  size_t histogram_bins_;
  std::vector<double> thresholds_m_;
  std::vector<size_t> within_;
  uint64_t points_ = 0;
  uint64_t beyond_ = 0;
  uint64_t kept_ = 0;
  double sum_signed_ = 0.0;
  double sum_abs_ = 0.0;
  double sum_squares_ = 0.0;
  double max_ = 0.0;
  Bin below_;  ///< under 2^-20 m, zero included
  Bin above_;  ///< 2^17 m and more
  /// An octave's bins are made when a distance first falls in it.
  std::array<std::unique_ptr<Bin[]>, kOctaves> octaves_;
};

}  // namespace featsense::mesh::internal
