#include "featsense/slam/trajectory/gyro_rotation.hpp"

#include <algorithm>
#include <cmath>

namespace featsense::slam {
namespace {

Eigen::Matrix3d exp_so3(const Eigen::Vector3d& rotation_vector) {
  const double angle = rotation_vector.norm();
  if (!(angle > 0.0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, rotation_vector / angle).toRotationMatrix();
}

struct RateSample {
  double t_s;
  Eigen::Vector3d rate;
};

/// The rate at t: linear between samples, constant beyond the ends.
Eigen::Vector3d rate_at(const std::vector<RateSample>& s, double t) {
  if (t <= s.front().t_s) return s.front().rate;
  if (t >= s.back().t_s) return s.back().rate;
  const auto after = std::upper_bound(s.begin(), s.end(), t,
                                      [](double x, const RateSample& r) { return x < r.t_s; });
  const RateSample& b = *after;
  const RateSample& a = *(after - 1);
  const double w = (t - a.t_s) / (b.t_s - a.t_s);
  return (1.0 - w) * a.rate + w * b.rate;
}

}  // namespace

std::optional<Eigen::Matrix3d> gyro_rotation(const std::vector<ImuSample>& earlier,
                                             const std::vector<ImuSample>& later, int64_t from_ns,
                                             int64_t to_ns) {
  const double period_s = static_cast<double>(to_ns - from_ns) * 1e-9;
  if (!(period_s > 0.0)) return std::nullopt;
  std::vector<RateSample> samples;
  for (const std::vector<ImuSample>* part : {&earlier, &later}) {
    for (const ImuSample& sample : *part) {
      const double t = static_cast<double>(sample.stamp_ns - from_ns) * 1e-9;
      // A sample out of order or repeated, or not a number, says nothing reliable.
      if (!sample.gyro_radps.allFinite() || (!samples.empty() && !(t > samples.back().t_s))) {
        continue;
      }
      samples.push_back({t, sample.gyro_radps});
    }
  }
  const double max_gap_s = 0.5 * period_s;
  if (samples.size() < 2 || samples.front().t_s > max_gap_s ||
      samples.back().t_s < period_s - max_gap_s) {
    return std::nullopt;
  }
  // The knots: the period's ends and the samples within it.
  std::vector<double> knots{0.0};
  for (const RateSample& s : samples) {
    if (s.t_s > 0.0 && s.t_s < period_s) knots.push_back(s.t_s);
  }
  knots.push_back(period_s);
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  for (size_t k = 1; k < knots.size(); ++k) {
    const double dt = knots[k] - knots[k - 1];
    if (dt > max_gap_s) return std::nullopt;
    // The midpoint rule on a linear rate is exact for the rate's integral.
    const Eigen::Vector3d mean_rate =
        0.5 * (rate_at(samples, knots[k - 1]) + rate_at(samples, knots[k]));
    rotation = rotation * exp_so3(mean_rate * dt);
  }
  return rotation;
}

Eigen::Isometry3d gyro_corrected_prediction(const Eigen::Isometry3d& predicted,
                                            const Eigen::Isometry3d& last_motion,
                                            const Eigen::Matrix3d& turn_before,
                                            const Eigen::Matrix3d& turn_now, double ratio) {
  // The gyroscope's error over the last period, as a rotation to apply after its turn.
  const Eigen::AngleAxisd bias(turn_before.transpose() * last_motion.linear());
  const Eigen::Matrix3d bias_now = exp_so3(ratio * bias.angle() * bias.axis());
  Eigen::Isometry3d corrected = predicted;
  corrected.linear() = turn_now * bias_now;
  return corrected;
}

}  // namespace featsense::slam
