#include "featsense/slam/sim/imu_simulator.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "featsense/slam/sim/measurement_model.hpp"

namespace featsense::slam {
namespace {

/// Hash purposes of the IMU's draws, apart from the LiDAR's (lidar_simulator.cpp).
enum ImuPurpose : uint32_t {
  kAccelNoise = 101,
  kGyroNoise = 102,
  kAccelBias = 103,
  kGyroBias = 104
};

/// The finite-difference step, seconds: small against the path's curvature, large against
/// the rounding of positions kilometres from the origin.
constexpr double kStep_s = 0.005;

/// A constant vector of length `magnitude` in a direction drawn from the seed.
Eigen::Vector3d drawn_bias(uint64_t seed, uint32_t purpose, double magnitude) {
  Eigen::Vector3d v;
  for (uint32_t axis = 0; axis < 3; ++axis) v[axis] = hashed_normal(seed, 0, 0, axis, purpose);
  return v.norm() > 0.0 ? Eigen::Vector3d(magnitude * v.normalized()) : Eigen::Vector3d::Zero();
}

Eigen::Vector3d drawn_noise(uint64_t seed, uint64_t sample, uint32_t purpose, double sigma) {
  Eigen::Vector3d v;
  for (uint32_t axis = 0; axis < 3; ++axis)
    v[axis] = sigma * hashed_normal(seed, sample, 1, axis, purpose);
  return v;
}

}  // namespace

ImuModel ImuModel::exact() {
  ImuModel model;
  model.accel_noise_mps2 = 0.0;
  model.accel_bias_mps2 = 0.0;
  model.gyro_noise_radps = 0.0;
  model.gyro_bias_radps = 0.0;
  return model;
}

std::vector<ImuSample> simulate_imu(const PoseCurve& path, const ImuModel& model, uint64_t seed,
                                    double t0_s, double t1_s, int64_t start_stamp_ns) {
  std::vector<ImuSample> samples;
  if (!model.enabled || !(model.rate_hz > 0.0) || !(t1_s > t0_s)) return samples;
  const double duration = path.duration_s();
  const Eigen::Vector3d accel_bias = drawn_bias(seed, kAccelBias, model.accel_bias_mps2);
  const Eigen::Vector3d gyro_bias = drawn_bias(seed, kGyroBias, model.gyro_bias_radps);
  const auto first = static_cast<uint64_t>(std::ceil(t0_s * model.rate_hz - 1e-9));
  for (uint64_t k = first;; ++k) {
    const double t = static_cast<double>(k) / model.rate_hz;
    // Within a nanosecond of t1 the sample is the next window's: t1 = start + period comes
    // out a rounding error above k / rate (0.2 + 0.1), and it would be in both.
    if (t >= t1_s - 1e-9) break;
    // Central differences inside the path, one-sided at its ends (the path is clamped there,
    // so a centred step would see a stop that is not in it).
    const double centre = std::clamp(t, kStep_s, std::max(kStep_s, duration - kStep_s));
    const Eigen::Isometry3d before = path.pose(centre - kStep_s);
    const Eigen::Isometry3d after = path.pose(centre + kStep_s);
    // The acceleration as an accelerometer reports it: filtered to its sample rate. The
    // second difference over one sample period each way is the acceleration averaged with a
    // triangle as wide as two periods; the samples' triangles add up to one everywhere, so the
    // readings integrate to the path's change of velocity exactly, also where a path of
    // sampled poses (a TUM file) bends at once between two samples. A narrower stencil would
    // see such a bend only from the samples next to it, and count it twice or not at all.
    const double period_s = 1.0 / model.rate_hz;
    const double middle = std::clamp(t, period_s, std::max(period_s, duration - period_s));
    const Eigen::Vector3d acceleration =
        (path.pose(middle + period_s).translation() - 2.0 * path.pose(middle).translation() +
         path.pose(middle - period_s).translation()) /
        (period_s * period_s);
    const Eigen::Matrix3d R = path.pose(t).rotation();
    const Eigen::AngleAxisd turn(before.rotation().transpose() * after.rotation());
    ImuSample sample;
    sample.stamp_ns = start_stamp_ns + static_cast<int64_t>(std::llround(t * 1e9));
    sample.accel_mps2 = R.transpose() * (acceleration + Eigen::Vector3d(0, 0, kStandardGravity)) +
                        accel_bias + drawn_noise(seed, k, kAccelNoise, model.accel_noise_mps2);
    sample.gyro_radps = turn.angle() / (2.0 * kStep_s) * turn.axis() + gyro_bias +
                        drawn_noise(seed, k, kGyroNoise, model.gyro_noise_radps);
    samples.push_back(sample);
  }
  return samples;
}

}  // namespace featsense::slam
