// azimuth_times(): per-point times of a spinning sensor's cloud from the points' azimuths
// and the order the file lists them in.

#include "featsense/slam/io/azimuth_times.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "featsense/slam/upper_median.hpp"
#include "point_validity.hpp"
#include "ring_turns.hpp"

namespace featsense::slam {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kRadPerDeg = M_PI / 180.0;

/// The first returns that tell where the sweep began: a firing of 16 beams or more, or the
/// first points of a ring.
constexpr size_t kSeamPoints = 16;
/// The beams of one firing lie this far apart in azimuth at most: their azimuth offsets
/// (HDL-64: -8.8 .. +9.9 deg, VLS-128 and Ouster: about +-6 and +-4 deg) and a little more.
constexpr double kFiringSpreadRad = 30.0 * kRadPerDeg;
/// A step back from one point to the next by less than this is the beams' offsets within a
/// firing, not points out of order (at most the 18.7 deg an HDL-64 firing spans).
constexpr double kOffsetStepRad = 25.0 * kRadPerDeg;
/// Files in measuring order step back further only at stray points (a few per mille);
/// points in random order step back further 43 % of the time, and so do points sorted by
/// anything but the azimuth.
constexpr double kMaxBackShare = 0.05;
/// A file that turns this many times is stored ring by ring, one turn per ring; one in
/// firing order turns once, a little more where beams' offsets run past the seam.
constexpr double kRingByRingTurns = 1.5;
/// Fewer returns than this show no order.
constexpr size_t kMinReturns = 32;

/// Clockwise from +x seen from above (+z), as scan columns run: [0, 2 pi).
double clockwise_rad(const Eigen::Vector3f& p) {
  double a = -std::atan2(static_cast<double>(p.y()), static_cast<double>(p.x()));
  if (a < 0.0) a += kTwoPi;
  return a < kTwoPi ? a : 0.0;
}

/// Into [0, 2 pi).
double wrap_positive(double a) {
  a = std::fmod(a, kTwoPi);
  if (a < 0.0) a += kTwoPi;
  return a < kTwoPi ? a : 0.0;
}

/// Into (-pi, pi]: the shorter way round.
double wrap_signed(double a) {
  a = wrap_positive(a);
  return a > M_PI ? a - kTwoPi : a;
}

/// Where the sweep began: the earliest azimuth of the cluster that most of the first
/// returns form (a stray first point does not move it); where they scatter (a ring with few
/// returns first, or points out of order, which the steps between them then show), the
/// first return's.
double find_seam(const std::vector<double>& clockwise) {
  const size_t n = std::min(kSeamPoints, clockwise.size());
  for (size_t centre = 0; centre < n; ++centre) {
    size_t members = 0;
    double earliest = 0.0;
    for (size_t j = 0; j < n; ++j) {
      const double d = wrap_signed(clockwise[j] - clockwise[centre]);
      if (std::abs(d) > kFiringSpreadRad) continue;
      ++members;
      earliest = std::min(earliest, d);
    }
    if (2 * members > n) return wrap_positive(clockwise[centre] + earliest);
  }
  return clockwise.front();
}

std::string percent(double share) {
  char text[16];
  std::snprintf(text, sizeof text, "%.0f %%", 100.0 * share);
  return text;
}

/// How far the rings begin before the seam, typically: the first ring's first returns may
/// be missing, and then the seam lies where most rings begin (radians, >= 0).
double rings_begin_before_seam_rad(const std::vector<double>& turned,
                                   const std::vector<size_t>& starts) {
  if (starts.empty()) return 0.0;
  std::vector<double> before;
  for (size_t r = 0; r < starts.size(); ++r) {
    before.push_back(kTwoPi * static_cast<double>(r + 1) - turned[starts[r]]);
  }
  return std::max(0.0, upper_median(before));
}

}  // namespace

AzimuthTimes azimuth_times(const std::vector<Eigen::Vector3f>& xyz, double rate_hz,
                           SweepReference reference) {
  AzimuthTimes out;
  out.reference = reference;
  std::vector<size_t> returns;  // indices into xyz, in file order
  std::vector<double> clockwise;
  std::vector<double> elevation;
  for (size_t i = 0; i < xyz.size(); ++i) {
    if (!is_return(xyz[i])) continue;
    returns.push_back(i);
    clockwise.push_back(clockwise_rad(xyz[i]));
    const Eigen::Vector3d p = xyz[i].cast<double>();
    elevation.push_back(std::atan2(p.z(), std::hypot(p.x(), p.y())));
  }
  if (!(rate_hz > 0.0)) {
    out.problem = "the sensor model has no rotation rate";
    return out;
  }
  const size_t n = returns.size();
  if (n < kMinReturns) {
    out.problem = "only " + std::to_string(n) + " returns, too few to show their order";
    return out;
  }
  const double seam = find_seam(clockwise);
  out.seam_rad = seam;

  // The angle turned since the seam along the file order, each step the shorter way round.
  std::vector<double> turned(n);
  turned[0] = wrap_signed(clockwise[0] - seam);
  size_t steps_back = 0;
  for (size_t k = 1; k < n; ++k) {
    const double step = wrap_signed(clockwise[k] - clockwise[k - 1]);
    if (step < -kOffsetStepRad) ++steps_back;
    turned[k] = turned[k - 1] + step;
  }
  const double back_share = static_cast<double>(steps_back) / static_cast<double>(n - 1);
  if (back_share > kMaxBackShare) {
    out.problem = "the points are not in the order they were measured: " + percent(back_share) +
                  " of the steps from one point to the next turn back (points sorted or "
                  "shuffled?)";
    return out;
  }
  const double turns = (turned.back() - turned.front()) / kTwoPi;
  if (!(turns > 0.0)) {
    out.problem = "the points run counterclockwise seen from above, against the sensor's turn";
    return out;
  }

  // Which turn each point belongs to: one in firing order; one per ring, each from the seam,
  // where the file lists the points ring by ring.
  std::vector<size_t> starts;
  if (turns >= kRingByRingTurns) {
    starts = ring_starts(turned, elevation);
    const double early_rad = rings_begin_before_seam_rad(turned, starts);
    out.seam_rad = wrap_positive(seam - early_rad);
    for (double& t : turned) t += early_rad;
  }
  out.sweeps = static_cast<int>(starts.size()) + 1;

  const double zero_rad =
      reference == SweepReference::kFacingForward ? wrap_positive(-out.seam_rad) : 0.0;
  const double seconds_per_rad = 1.0 / (kTwoPi * rate_hz);
  out.offset_s.assign(xyz.size(), 0.0f);
  size_t sweep = 0;
  for (size_t k = 0; k < n; ++k) {
    while (sweep < starts.size() && starts[sweep] <= k) ++sweep;
    double t = (turned[k] - kTwoPi * static_cast<double>(sweep) - zero_rad) * seconds_per_rad;
    // A beam's offset may put a point of the first firing before the seam; nothing was
    // measured before the sweep began.
    if (reference == SweepReference::kSweepStart) t = std::max(t, 0.0);
    out.offset_s[returns[k]] = static_cast<float>(t);
  }
  return out;
}

std::string describe(const AzimuthTimes& times) {
  if (!times.found()) return "none: " + times.problem;
  char text[200];
  const std::string order = times.sweeps == 1
                                ? std::string("points in firing order")
                                : std::to_string(times.sweeps) + " rings one after another";
  std::snprintf(text, sizeof text,
                "from the azimuth (the sweep began %.1f deg clockwise of +x, %s; 0 s %s)",
                times.seam_rad / kRadPerDeg, order.c_str(),
                times.reference == SweepReference::kSweepStart ? "where it began"
                                                               : "where the sensor faced +x");
  return text;
}

std::string describe_times(const std::string& time_field, const AzimuthTimes* derived) {
  if (!time_field.empty()) return "per-point field '" + time_field + "'";
  if (derived) return describe(*derived);
  return "none: no time field, and sensor.times_from_azimuth is false";
}

}  // namespace featsense::slam
