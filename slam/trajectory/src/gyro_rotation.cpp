#include "featsense/slam/trajectory/gyro_rotation.hpp"

#include <algorithm>
#include <cmath>

#include "gyro_samples.hpp"

namespace featsense::slam {
namespace {

/// The rate at t: linear between samples, constant beyond the ends.
Eigen::Vector3d rate_at(const gyro::Rates& s, double t) {
  const std::vector<double>& times = s.times_s;
  if (t <= times.front()) return s.rates.front();
  if (t >= times.back()) return s.rates.back();
  const size_t b =
      static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const size_t a = b - 1;
  const double w = (t - times[a]) / (times[b] - times[a]);
  return (1.0 - w) * s.rates[a] + w * s.rates[b];
}

}  // namespace

std::optional<Eigen::Matrix3d> gyro_rotation(const std::vector<ImuSample>& earlier,
                                             const std::vector<ImuSample>& later, int64_t from_ns,
                                             int64_t to_ns) {
  const double period_s = static_cast<double>(to_ns - from_ns) * 1e-9;
  const std::optional<GyroTurn> turn = gyro_turn(earlier, later, from_ns, to_ns, 0.5 * period_s);
  if (!turn) return std::nullopt;
  return turn->rotation;
}

std::optional<GyroTurn> gyro_turn(const std::vector<ImuSample>& earlier,
                                  const std::vector<ImuSample>& later, int64_t from_ns,
                                  int64_t to_ns, double max_gap_s) {
  const double period_s = static_cast<double>(to_ns - from_ns) * 1e-9;
  if (!(period_s > 0.0)) return std::nullopt;
  const gyro::Rates samples = gyro::merged_rates(earlier, later, from_ns);
  const std::vector<double>& times = samples.times_s;
  if (times.size() < 2 || times.front() > max_gap_s || times.back() < period_s - max_gap_s) {
    return std::nullopt;
  }
  // The knots: the period's ends and the samples within it.
  std::vector<double> knots{0.0};
  for (const double t : times) {
    if (t > 0.0 && t < period_s) knots.push_back(t);
  }
  knots.push_back(period_s);
  GyroTurn turn;
  for (size_t k = 1; k < knots.size(); ++k) {
    const double dt = knots[k] - knots[k - 1];
    if (dt > max_gap_s) return std::nullopt;
    // The midpoint rule on a linear rate is exact for the rate's integral.
    const Eigen::Vector3d mean_rate =
        0.5 * (rate_at(samples, knots[k - 1]) + rate_at(samples, knots[k]));
    const Eigen::Matrix3d step = gyro::rotation_of(mean_rate * dt);
    turn.rotation = turn.rotation * step;
    // A bias b turns each step by Exp(-b dt); moved past the later steps, the chain's
    // Jacobian follows J <- E^T J + dt I (the step's right Jacobian taken as I: steps of a
    // hundredth of a radian).
    turn.bias_jacobian = step.transpose() * turn.bias_jacobian + dt * Eigen::Matrix3d::Identity();
  }
  return turn;
}

Eigen::Isometry3d gyro_corrected_prediction(const Eigen::Isometry3d& predicted,
                                            const Eigen::Isometry3d& last_motion,
                                            const Eigen::Matrix3d& turn_before,
                                            const Eigen::Matrix3d& turn_now, double ratio) {
  // The gyroscope's error over the last period, as a rotation to apply after its turn.
  const Eigen::AngleAxisd bias(turn_before.transpose() * last_motion.linear());
  const Eigen::Matrix3d bias_now = gyro::rotation_of(ratio * bias.angle() * bias.axis());
  Eigen::Isometry3d corrected = predicted;
  corrected.linear() = turn_now * bias_now;
  return corrected;
}

}  // namespace featsense::slam
