#include "featsense/slam/loops/gyro_reference.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <optional>
#include <vector>

#include "featsense/slam/loops/gravity_reference.hpp"
#include "featsense/slam/trajectory/gyro_rotation.hpp"
#include "robust_spread.hpp"

namespace featsense::slam::loops {
namespace {

double seconds(int64_t ns) { return static_cast<double>(ns) * 1e-9; }

/// Fewer edges than this tell too little about the two sensors' agreement: left as modelled.
constexpr size_t kMinEdgesToWeigh = 10;
/// The LiDAR's error is taken as at least this share of the sigma the graph gives it.
constexpr double kLidarFloorShare = 0.1;
/// A disagreement beyond this many times what the two claim together is not noise.
constexpr double kInconsistent = 5.0;

}  // namespace

std::vector<GyroObservation> gyro_observations(const std::vector<ImuSample>& samples,
                                               const std::vector<int64_t>& keyframe_stamps_ns,
                                               const GyroSettings& settings) {
  std::vector<GyroObservation> out;
  if (!settings.enabled || samples.size() < 2 || keyframe_stamps_ns.size() < 2) return out;
  const int64_t period_ns = median_sample_period_ns(samples);
  if (period_ns <= 0) return out;
  const double max_gap_s = settings.max_gap_periods * seconds(period_ns);
  const auto by_stamp = [](const ImuSample& s, int64_t t) { return s.stamp_ns < t; };

  for (size_t k = 1; k < keyframe_stamps_ns.size(); ++k) {
    const int64_t t0 = keyframe_stamps_ns[k - 1], t1 = keyframe_stamps_ns[k];
    if (t1 <= t0) continue;
    // The samples around [t0, t1]: the last at or before t0 to the first at or after t1.
    auto first = std::lower_bound(samples.begin(), samples.end(), t0, by_stamp);
    if (first == samples.end()) continue;  // keyframes need not be in time order (sessions)
    if (first->stamp_ns > t0) {
      if (first == samples.begin()) continue;
      --first;
    }
    auto last = std::lower_bound(first, samples.end(), t1, by_stamp);
    if (last == samples.end()) continue;
    // The chain of the samples over [t0, t1] (gyro_rotation's), with its bias Jacobian.
    const std::vector<ImuSample> span_samples(first, std::next(last));
    const std::optional<GyroTurn> chained = gyro_turn(span_samples, {}, t0, t1, max_gap_s);
    if (!chained) continue;
    GyroObservation o;
    o.from = k - 1;
    o.to = k;
    o.delta = chained->rotation;
    o.bias_jacobian = chained->bias_jacobian;
    const double span = seconds(t1 - t0);
    const double turn = Eigen::AngleAxisd(o.delta).angle();
    const Eigen::Vector3d rate_change =
        (last == first ? Eigen::Vector3d::Zero()
                       : Eigen::Vector3d(last->gyro_radps - first->gyro_radps));
    const double white = settings.noise_radps * std::sqrt(seconds(period_ns) * span);
    const double mounting = settings.turn_fraction * turn;
    const double clock = settings.clock_offset_s * rate_change.norm();
    o.noise_rad = std::sqrt(white * white + settings.min_sigma_rad * settings.min_sigma_rad);
    o.sigma_rad.setConstant(
        std::sqrt(o.noise_rad * o.noise_rad + mounting * mounting + clock * clock));
    out.push_back(o);
  }
  return out;
}

TurnAgreement weigh_against_lidar(std::vector<GyroObservation>* turns,
                                  const std::vector<LidarTurn>& lidar) {
  TurnAgreement agreement;
  if (turns->size() != lidar.size() || turns->size() < kMinEdgesToWeigh) return agreement;
  const size_t n = turns->size();
  // The LiDAR's turn against the gyroscope's, per edge: Log(delta^T R_lidar) = -J b + e.
  std::vector<Eigen::Vector3d> misfit(n);
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const GyroObservation& turn = (*turns)[i];
    const Eigen::AngleAxisd error(turn.delta.transpose() * lidar[i].rotation);
    misfit[i] = error.angle() * error.axis();
    normal += turn.bias_jacobian.transpose() * turn.bias_jacobian;
    rhs += turn.bias_jacobian.transpose() * misfit[i];
  }
  const Eigen::LDLT<Eigen::Matrix3d> solver(normal);
  if (solver.info() != Eigen::Success) return agreement;
  agreement.bias_radps = -solver.solve(rhs);
  if (!agreement.bias_radps.allFinite()) return agreement;
  // Per axis, a robust variance (the median square over the median of chi^2 with one degree
  // of freedom, 0.455: a jolt or two do not count), less the gyroscope's own noise.
  double noise2 = 0.0;
  for (const GyroObservation& turn : *turns) noise2 += turn.noise_rad * turn.noise_rad;
  noise2 /= static_cast<double>(n);
  Eigen::Vector3d claimed2 = Eigen::Vector3d::Zero();
  for (const LidarTurn& turn : lidar) claimed2 += turn.sigma_rad.cwiseAbs2();
  claimed2 /= static_cast<double>(n);
  std::vector<double> squares(n);
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < n; ++i) {
      const double e = misfit[i](axis) + ((*turns)[i].bias_jacobian * agreement.bias_radps)(axis);
      squares[i] = e * e;
    }
    const double variance = robust_variance(squares);
    agreement.disagreement_rad(axis) = std::sqrt(variance);
    // The LiDAR's error: what the gyroscope's noise leaves, at least a tenth of the graph's.
    const double floor = kLidarFloorShare * std::sqrt(claimed2(axis));
    agreement.lidar_sigma_rad(axis) = std::sqrt(std::max(variance - noise2, floor * floor));
  }
  // What the two claim together, per axis: the graph's LiDAR sigma and the gyroscope's model.
  Eigen::Vector3d gyro2 = Eigen::Vector3d::Zero();
  for (const GyroObservation& turn : *turns) gyro2 += turn.sigma_rad.cwiseAbs2();
  gyro2 /= static_cast<double>(n);
  const Eigen::Vector3d claimed_together = (claimed2 + gyro2).cwiseSqrt();
  agreement.edges = n;
  if ((agreement.disagreement_rad.array() > kInconsistent * claimed_together.array()).any()) {
    agreement.consistent = false;
    return agreement;
  }
  for (size_t i = 0; i < n; ++i) {
    GyroObservation& turn = (*turns)[i];
    for (int axis = 0; axis < 3; ++axis) {
      const double ratio = lidar[i].sigma_rad(axis) / agreement.lidar_sigma_rad(axis);
      turn.sigma_rad(axis) *= std::max(1.0, ratio);
    }
  }
  return agreement;
}

}  // namespace featsense::slam::loops
