#include "featsense/slam/trajectory/sweep_motion.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "featsense/slam/trajectory/pose_interpolation.hpp"
#include "gyro_samples.hpp"

namespace featsense::slam {
namespace {

/// The integral of a rate that is linear between samples (times t, rates r, integrals
/// `integral` at the samples) and constant beyond the ends, at time x.
Eigen::Vector3d integral_at(const std::vector<double>& t, const std::vector<Eigen::Vector3d>& r,
                            const std::vector<Eigen::Vector3d>& integral, double x) {
  const size_t n = t.size();
  if (x <= t.front()) return integral.front() + r.front() * (x - t.front());
  if (x >= t.back()) return integral.back() + r.back() * (x - t.back());
  size_t k = 0;
  while (k + 2 < n && t[k + 1] <= x) ++k;
  const double h = t[k + 1] - t[k];
  const double d = x - t[k];
  return integral[k] + r[k] * d + (r[k + 1] - r[k]) * (0.5 * d * d / h);
}

}  // namespace

GyroTwist GyroTwist::from_samples(const std::vector<ImuSample>& earlier,
                                  const std::vector<ImuSample>& later, int64_t period_from_ns,
                                  int64_t period_to_ns, int64_t stamp_ns) {
  GyroTwist twist;
  const double period_s = static_cast<double>(period_to_ns - period_from_ns) * 1e-9;
  if (!(period_s > 0.0)) return twist;
  // The period and the sweep's first half, in seconds from the stamp.
  const double from_s = static_cast<double>(period_from_ns - stamp_ns) * 1e-9;
  const double to_s = from_s + period_s;
  const double needed_from_s = std::min(from_s, 0.0);
  const double needed_to_s = std::max(to_s, 0.5 * period_s);
  gyro::Rates merged = gyro::merged_rates(earlier, later, stamp_ns);
  std::vector<double>& t = merged.times_s;
  std::vector<Eigen::Vector3d>& rate = merged.rates;
  // The rate must be known over the period (for its mean) and over the sweep's first half at
  // least: no gap of more than half a period.
  const double max_gap_s = 0.5 * period_s;
  if (t.size() < 2 || t.front() > needed_from_s + max_gap_s || t.back() < needed_to_s - max_gap_s) {
    return twist;
  }
  for (size_t k = 1; k < t.size(); ++k) {
    const bool relevant = t[k] > needed_from_s && t[k - 1] < needed_to_s;
    if (relevant && t[k] - t[k - 1] > max_gap_s) return twist;
  }
  std::vector<Eigen::Vector3d> integral(t.size(), Eigen::Vector3d::Zero());
  for (size_t k = 1; k < t.size(); ++k) {
    integral[k] = integral[k - 1] + 0.5 * (rate[k] + rate[k - 1]) * (t[k] - t[k - 1]);
  }
  const Eigen::Vector3d at_stamp = integral_at(t, rate, integral, 0.0);
  const Eigen::Vector3d mean =
      (integral_at(t, rate, integral, to_s) - integral_at(t, rate, integral, from_s)) / period_s;
  twist.times_s_ = std::move(t);
  twist.rates_.reserve(rate.size());
  twist.twists_.reserve(rate.size());
  for (size_t k = 0; k < twist.times_s_.size(); ++k) {
    twist.rates_.push_back(rate[k] - mean);
    twist.twists_.push_back(integral[k] - at_stamp - mean * twist.times_s_[k]);
  }
  return twist;
}

Eigen::Vector3d GyroTwist::at(double t_s) const {
  if (empty()) return Eigen::Vector3d::Zero();
  return integral_at(times_s_, rates_, twists_, t_s);
}

SweepMotion::SweepMotion(const Eigen::Isometry3d& motion, double period_s, GyroTwist twist)
    : motion_(motion), period_s_(period_s > 0.0 ? period_s : 0.0), twist_(std::move(twist)) {
  const Eigen::AngleAxisd turn(Eigen::Quaterniond(motion.linear()).normalized());
  rotation_vector_ = turn.angle() * turn.axis();
}

Eigen::Isometry3d SweepMotion::at(double t_s) const {
  if (!moving()) return Eigen::Isometry3d::Identity();
  const double s = t_s / period_s_;
  if (twist_.empty()) return motion_fraction(motion_, s);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = gyro::rotation_of(s * rotation_vector_ + twist_.at(t_s));
  pose.translation() = s * motion_.translation();
  return pose;
}

}  // namespace featsense::slam
