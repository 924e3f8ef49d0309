#include "featsense/slam/loops/gravity_reference.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "featsense/slam/loops/trajectory_correction.hpp"

namespace featsense::slam::loops {
namespace {

double seconds(int64_t ns) { return static_cast<double>(ns) * 1e-9; }

/// The path's pose at `t_ns`, interpolated between its stamps (held at its ends).
class PathAt {
 public:
  PathAt(const std::vector<int64_t>& stamps_ns, const std::vector<Eigen::Isometry3d>& poses)
      : stamps_(stamps_ns), poses_(poses) {}

  Eigen::Isometry3d operator()(int64_t t_ns) const {
    const auto after = std::lower_bound(stamps_.begin(), stamps_.end(), t_ns);
    if (after == stamps_.begin()) return poses_.front();
    if (after == stamps_.end()) return poses_.back();
    const auto i = static_cast<size_t>(std::distance(stamps_.begin(), after));
    const double s = static_cast<double>(t_ns - stamps_[i - 1]) /
                     static_cast<double>(stamps_[i] - stamps_[i - 1]);
    return interpolate_pose(poses_[i - 1], poses_[i], s);
  }

  /// A mean velocity between two stamps, and the instant it stands for (the middle: exact
  /// under constant acceleration). Taken between stamps, not interpolated positions: a chord
  /// between stamps cuts the corner of a turn by millimetres.
  struct Velocity {
    Eigen::Vector3d mps;
    int64_t at_ns = 0;
  };
  Velocity between(size_t a, size_t b) const {
    return {(poses_[b].translation() - poses_[a].translation()) / seconds(stamps_[b] - stamps_[a]),
            stamps_[a] + (stamps_[b] - stamps_[a]) / 2};
  }
  /// The first stamp at or after `t_ns` (size() when none).
  size_t at_or_after(int64_t t_ns) const {
    return static_cast<size_t>(
        std::distance(stamps_.begin(), std::lower_bound(stamps_.begin(), stamps_.end(), t_ns)));
  }
  size_t size() const { return stamps_.size(); }

 private:
  const std::vector<int64_t>& stamps_;
  const std::vector<Eigen::Isometry3d>& poses_;
};

}  // namespace

void append_in_time_order(std::vector<ImuSample>* log, const std::vector<ImuSample>& more) {
  for (const ImuSample& sample : more) {
    if (log->empty() || sample.stamp_ns > log->back().stamp_ns) log->push_back(sample);
  }
}

std::vector<GravityObservation> gravity_observations(const std::vector<int64_t>& path_stamps_ns,
                                                     const std::vector<Eigen::Isometry3d>& path,
                                                     const std::vector<ImuSample>& samples,
                                                     const std::vector<int64_t>& keyframe_stamps_ns,
                                                     const GravitySettings& settings) {
  std::vector<GravityObservation> out;
  if (!settings.enabled || samples.size() < 2 || path.size() < 2 ||
      path_stamps_ns.size() != path.size())
    return out;
  const int64_t span_ns = path_stamps_ns.back() - path_stamps_ns.front();
  const auto baseline_ns = static_cast<int64_t>(settings.velocity_baseline_s * 1e9);
  if (span_ns <= baseline_ns) return out;
  // The IMU's sample period, from the median spacing (robust to a gap).
  std::vector<int64_t> spacing;
  for (size_t i = 1; i < samples.size(); ++i)
    spacing.push_back(samples[i].stamp_ns - samples[i - 1].stamp_ns);
  std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
  const int64_t period_ns = spacing[spacing.size() / 2];
  if (period_ns <= 0) return out;
  const auto window_ns = static_cast<int64_t>(settings.window_s * 1e9);
  const auto wanted = static_cast<size_t>(settings.window_s / seconds(period_ns));

  const PathAt path_at(path_stamps_ns, path);
  const auto by_stamp = [](const ImuSample& s, int64_t t) { return s.stamp_ns < t; };
  for (size_t k = 0; k < keyframe_stamps_ns.size(); ++k) {
    // The window around the keyframe, slid to stay within the path; its ends are the instants
    // of two mean velocities between stamps a baseline apart.
    int64_t from = keyframe_stamps_ns[k] - window_ns / 2;
    from = std::max(path_stamps_ns.front(), std::min(from, path_stamps_ns.back() - window_ns));
    const size_t a0 = path_at.at_or_after(from);
    const size_t a1 =
        path_at.at_or_after(path_stamps_ns[std::min(a0, path.size() - 1)] + baseline_ns);
    const size_t b1 = path_at.at_or_after(from + window_ns);
    if (a1 >= path.size() || b1 >= path.size()) continue;
    const size_t b0 = path_at.at_or_after(path_stamps_ns[b1] - baseline_ns);
    if (a1 <= a0 || b1 <= b0 || b0 <= a0) continue;
    const PathAt::Velocity v_start = path_at.between(a0, a1);
    const PathAt::Velocity v_end = path_at.between(b0, b1);
    if (v_end.at_ns <= v_start.at_ns) continue;
    // The samples over [start, end], and one on either side to reach its ends.
    const auto after_start =
        std::upper_bound(samples.begin(), samples.end(), v_start.at_ns,
                         [](int64_t t, const ImuSample& s) { return t < s.stamp_ns; });
    const auto end_sample = std::lower_bound(after_start, samples.end(), v_end.at_ns, by_stamp);
    if (after_start == samples.begin() || end_sample == samples.end()) continue;
    const auto first = std::prev(after_start);
    const auto last = std::next(end_sample);
    const auto n = static_cast<size_t>(std::distance(after_start, end_sample));
    if (n < 10 || 2 * n < wanted || first->stamp_ns < v_start.at_ns - 2 * period_ns ||
        end_sample->stamp_ns > v_end.at_ns + 2 * period_ns)
      continue;
    const Eigen::Matrix3d R_k_map = path_at(keyframe_stamps_ns[k]).rotation().transpose();
    GravityObservation o;
    o.node = k;
    o.samples = n;
    // The trapezoid rule over [start, end] between the samples, exact for a force that
    // changes linearly between them: a sample is a reading at its instant, not a period's.
    o.mean_force.setZero();
    o.bias_rotation.setZero();
    Eigen::Matrix3d R_previous = R_k_map * path_at(first->stamp_ns).rotation();
    for (auto s = first, next = std::next(first); next != last; s = next, ++next) {
      const Eigen::Matrix3d R_next = R_k_map * path_at(next->stamp_ns).rotation();
      const double t0 = seconds(s->stamp_ns), t1 = seconds(next->stamp_ns);
      const double u = std::max(t0, seconds(v_start.at_ns));
      const double w = std::min(t1, seconds(v_end.at_ns));
      if (w > u) {
        const auto at = [&](double t, const auto& a, const auto& b) {
          const double f = (t - t0) / (t1 - t0);
          return ((1.0 - f) * a + f * b).eval();
        };
        const Eigen::Vector3d force0 = R_previous * s->accel_mps2;
        const Eigen::Vector3d force1 = R_next * next->accel_mps2;
        o.mean_force += 0.5 * (w - u) * (at(u, force0, force1) + at(w, force0, force1));
        o.bias_rotation += 0.5 * (w - u) * (at(u, R_previous, R_next) + at(w, R_previous, R_next));
      }
      R_previous = R_next;
    }
    const int64_t start = v_start.at_ns;
    const int64_t end = v_end.at_ns;
    const double duration = seconds(end - start);
    o.mean_force /= duration;
    o.bias_rotation /= duration;
    o.velocity_change = R_k_map * (v_end.mps - v_start.mps) / duration;
    // The noise of the mean force, of the velocity change and the floor, as an angle; the
    // windows of the keyframes around share their samples, so each counts for a share.
    const double accel = settings.accel_noise_mps2 / std::sqrt(static_cast<double>(n));
    const double velocity = std::sqrt(2.0) * settings.velocity_sigma_mps / duration;
    const double up = std::max(o.up().norm(), 1.0);
    const auto shared = static_cast<double>(
        std::upper_bound(keyframe_stamps_ns.begin(), keyframe_stamps_ns.end(), end) -
        std::lower_bound(keyframe_stamps_ns.begin(), keyframe_stamps_ns.end(), start));
    o.sigma_rad = std::sqrt(accel * accel + velocity * velocity +
                            settings.min_sigma_mps2 * settings.min_sigma_mps2) /
                  up * std::sqrt(std::max(1.0, shared));
    out.push_back(o);
  }
  return out;
}

}  // namespace featsense::slam::loops
