#include "internal/distance_accumulator.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace featsense::mesh::internal {
namespace {

/// The exponent field of 2^-20 in a float (bias 127).
constexpr uint32_t kFirstExponent = 127 - 20;

}  // namespace

DistanceAccumulator::DistanceAccumulator(const CompareSettings& settings)
    : max_dist_m_(settings.max_dist_m),
      histogram_bins_(settings.histogram_bins),
      thresholds_m_(settings.thresholds_m),
      within_(settings.thresholds_m.size(), 0) {}

DistanceAccumulator::Bin& DistanceAccumulator::bin_of(float magnitude) {
  uint32_t bits = 0;
  std::memcpy(&bits, &magnitude, sizeof bits);
  const uint32_t exponent = bits >> 23;
  if (exponent < kFirstExponent) return below_;
  const uint32_t octave = exponent - kFirstExponent;
  if (octave >= static_cast<uint32_t>(kOctaves)) return above_;
  std::unique_ptr<Bin[]>& bins = octaves_[octave];
  if (!bins) bins = std::make_unique<Bin[]>(kBinsPerOctave);
  return bins[(bits >> (23 - kMantissaBits)) & (kBinsPerOctave - 1)];
}

void DistanceAccumulator::add(float unsigned_m, float signed_m) {
  ++points_;
  for (size_t k = 0; k < thresholds_m_.size(); ++k) {
    if (unsigned_m <= thresholds_m_[k]) ++within_[k];
  }
  if (max_dist_m_ > 0.0 && unsigned_m > max_dist_m_) {
    ++beyond_;
    return;
  }
  // As the figures have always been taken: |d| from the signed value.
  const double d = signed_m;
  const double magnitude = std::abs(d);
  ++kept_;
  sum_signed_ += d;
  sum_abs_ += magnitude;
  sum_squares_ += d * d;
  max_ = std::max(max_, magnitude);
  Bin& bin = bin_of(std::abs(signed_m));
  ++bin.count;
  bin.sum += magnitude;
}

double DistanceAccumulator::ranked(uint64_t rank) const {
  const auto mean_if_there = [&rank](const Bin& bin, double* value) {
    if (rank < bin.count) {
      *value = bin.sum / static_cast<double>(bin.count);
      return true;
    }
    rank -= bin.count;
    return false;
  };
  double value = 0.0;
  if (mean_if_there(below_, &value)) return value;
  for (const std::unique_ptr<Bin[]>& bins : octaves_) {
    if (!bins) continue;
    for (size_t b = 0; b < kBinsPerOctave; ++b) {
      if (mean_if_there(bins[b], &value)) return value;
    }
  }
  mean_if_there(above_, &value);
  return value;
}

void DistanceAccumulator::fill(CompareResult* result) const {
  result->points = points_;
  result->beyond_max_dist = beyond_;
  DistanceStatistics& s = result->accuracy;
  s = DistanceStatistics();
  if (kept_ > 0) {
    const auto n = static_cast<double>(kept_);
    s.count = kept_;
    s.mean_signed = sum_signed_ / n;
    s.mean_abs = sum_abs_ / n;
    s.rmse = std::sqrt(sum_squares_ / n);
    // Population deviations from the sums (|d|^2 = d^2), never below zero by rounding.
    s.std_signed = std::sqrt(std::max(0.0, sum_squares_ / n - s.mean_signed * s.mean_signed));
    s.std_abs = std::sqrt(std::max(0.0, sum_squares_ / n - s.mean_abs * s.mean_abs));
    const uint64_t half = kept_ / 2;
    s.median = kept_ % 2 == 1 ? ranked(half) : 0.5 * (ranked(half - 1) + ranked(half));
    const auto rank = static_cast<uint64_t>(std::ceil(0.95 * n));  // nearest rank, 1-based
    s.p95 = ranked(std::max<uint64_t>(rank, 1) - 1);
    s.max = max_;
  }
  result->histogram_edges_m.clear();
  result->histogram_counts.clear();
  if (histogram_bins_ == 0) return;
  double top = max_dist_m_ > 0.0 ? max_dist_m_ : s.max;
  if (!(top > 0.0)) top = 1e-3;  // every point on the surface: one narrow bin holds them all
  const auto bins = static_cast<double>(histogram_bins_);
  for (size_t b = 0; b <= histogram_bins_; ++b) {
    result->histogram_edges_m.push_back(top * static_cast<double>(b) / bins);
  }
  result->histogram_counts.assign(histogram_bins_, 0);
  const auto count_in = [&](const Bin& bin) {
    if (bin.count == 0) return;
    const double value = bin.sum / static_cast<double>(bin.count);
    const auto coarse = static_cast<size_t>(value / top * bins);
    result->histogram_counts[std::min(coarse, histogram_bins_ - 1)] += bin.count;
  };
  count_in(below_);
  for (const std::unique_ptr<Bin[]>& octave : octaves_) {
    if (!octave) continue;
    for (size_t b = 0; b < kBinsPerOctave; ++b) count_in(octave[b]);
  }
  count_in(above_);
}

}  // namespace featsense::mesh::internal
