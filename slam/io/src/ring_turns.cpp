// ring_starts(): where each ring begins in a cloud stored ring by ring.

#include "ring_turns.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "featsense/slam/upper_median.hpp"

namespace featsense::slam {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
/// Rings that begin right at the seam reach the next whole turn give or take float rounding
/// (a few 1e-7 rad).
constexpr double kSeamRoundingRad = 1e-5;
/// How far from the seam one ring's last and the next ring's first points may lie: beams'
/// azimuth offsets (up to 10 deg) and returns missing where the first ring began.
constexpr double kSeamWindowRad = 45.0 * M_PI / 180.0;
/// The returns of a ring beside the seam that tell its elevation there: the ring's points
/// beside the seam see the same surfaces (a ring's elevation varies with range where the
/// beam starts off the sensor's origin, as the HDL-64's do by 0.1 - 0.2 m).
constexpr size_t kBesidePoints = 32;
constexpr size_t kMinBesidePoints = 8;
/// Two rings' elevations beside the seam must differ by more than this and twice their
/// spread to be told apart (rad).
constexpr double kMinElevationGapRad = 1e-4;

/// The returns around one whole turn past the seam, [begin, end), and the first one past it.
struct SeamWindow {
  size_t begin = 0;
  size_t crossing = 0;
  size_t end = 0;
};

struct Spread {
  double median = 0.0;
  double deviation = 0.0;  ///< median absolute deviation
};

std::optional<Spread> spread_of(std::vector<double> values) {
  if (values.size() < kMinBesidePoints) return std::nullopt;
  Spread spread;
  spread.median = upper_median(values);
  for (double& v : values) v = std::abs(v - spread.median);
  spread.deviation = upper_median(values);
  return spread;
}

std::vector<SeamWindow> seam_windows(const std::vector<double>& turned) {
  std::vector<SeamWindow> windows;
  const size_t n = turned.size();
  size_t previous_end = 0;
  for (size_t k = 1; k < n; ++k) {
    const double seam = kTwoPi * static_cast<double>(windows.size() + 1);
    if (turned[k] < seam - kSeamRoundingRad) continue;
    SeamWindow w{k, k, k + 1};
    while (w.begin > previous_end && turned[w.begin - 1] >= seam - kSeamWindowRad) --w.begin;
    while (w.end < n && turned[w.end] < seam + kSeamWindowRad) ++w.end;
    // Past the seam at the end of the file: the last ring running past it, not a new one.
    if (w.end == n) break;
    windows.push_back(w);
    previous_end = w.end;
    k = w.end - 1;  // the next whole turn lies beyond the window
  }
  return windows;
}

/// The first return of the later ring within `w`: the split that leaves the fewest returns
/// on the side of the ring whose elevation is further from theirs; of equals, the one
/// nearest to the crossing.
size_t split_by_elevation(const SeamWindow& w, const Spread& before, const Spread& after,
                          const std::vector<double>& elevation_rad) {
  // Cost of a split at s: returns before s nearer the later ring, and from s on nearer the
  // earlier one. Moving s past a return changes it by +1 or -1 (or 0 for a tie).
  int cost = 0;
  std::vector<int> change;
  change.reserve(w.end - w.begin);
  for (size_t i = w.begin; i < w.end; ++i) {
    const double to_before = std::abs(elevation_rad[i] - before.median);
    const double to_after = std::abs(elevation_rad[i] - after.median);
    change.push_back(to_after < to_before ? 1 : to_before < to_after ? -1 : 0);
    if (to_before < to_after) ++cost;
  }
  size_t best = w.begin;
  int best_cost = cost;
  for (size_t s = w.begin + 1; s <= w.end; ++s) {
    cost += change[s - 1 - w.begin];
    const auto distance = [&w](size_t at) {
      return at > w.crossing ? at - w.crossing : w.crossing - at;
    };
    if (cost < best_cost || (cost == best_cost && distance(s) < distance(best))) {
      best = s;
      best_cost = cost;
    }
  }
  return best;
}

}  // namespace

std::vector<size_t> ring_starts(const std::vector<double>& turned,
                                const std::vector<double>& elevation_rad) {
  const std::vector<SeamWindow> windows = seam_windows(turned);
  auto elevations = [&elevation_rad](size_t from, size_t to) {
    return std::vector<double>(elevation_rad.begin() + static_cast<std::ptrdiff_t>(from),
                               elevation_rad.begin() + static_cast<std::ptrdiff_t>(to));
  };
  std::vector<size_t> starts;
  for (size_t r = 0; r < windows.size(); ++r) {
    const SeamWindow& w = windows[r];
    const size_t ring_begin = r == 0 ? 0 : windows[r - 1].end;
    const size_t next_ring_end = r + 1 < windows.size() ? windows[r + 1].begin : turned.size();
    const std::optional<Spread> before =
        spread_of(elevations(w.begin - std::min(kBesidePoints, w.begin - ring_begin), w.begin));
    const std::optional<Spread> after =
        spread_of(elevations(w.end, w.end + std::min(kBesidePoints, next_ring_end - w.end)));
    size_t start = w.crossing;
    if (before && after &&
        std::abs(before->median - after->median) >
            2.0 * std::max(before->deviation, after->deviation) + kMinElevationGapRad) {
      start = split_by_elevation(w, *before, *after, elevation_rad);
    }
    starts.push_back(start);
  }
  return starts;
}

}  // namespace featsense::slam
