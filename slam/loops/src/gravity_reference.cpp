#include "featsense/slam/loops/gravity_reference.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <utility>
#include <vector>

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

/// The weight with which the acceleration at time t enters the difference of the mean
/// velocities over [a0, a1] and [b0, b1] (a0 < a1 and a0 < b0 < b1): with
/// v(t) = v(a0) + int_a0^t a, mean_b - mean_a = int a(s) w(s) ds, where w rises linearly from
/// 0 at a0 to 1 at a1, is 1 up to b0 and falls to 0 at b1 (both parts added where the
/// baselines overlap). Its integral is the time between the baselines' middles.
struct AccelerationKernel {
  int64_t a0, a1, b0, b1;

  double weight(double t_s) const {
    const double A0 = seconds(a0), A1 = seconds(a1), B0 = seconds(b0), B1 = seconds(b1);
    double w = 0.0;
    if (t_s >= A0 && t_s < B0) w += 1.0;  // half open: the last part takes over at B0
    if (t_s >= A0 && t_s <= A1) w -= (A1 - t_s) / (A1 - A0);
    if (t_s >= B0 && t_s <= B1) w += (B1 - t_s) / (B1 - B0);
    return w;
  }

  /// [t0, t1] clipped to [a0, b1] and cut at the kernel's corners: pieces on which it is
  /// linear.
  std::vector<std::pair<int64_t, int64_t>> pieces(int64_t t0, int64_t t1) const {
    std::vector<int64_t> cuts = {std::max(t0, a0), std::min(t1, b1)};
    if (cuts[1] <= cuts[0]) return {};
    for (const int64_t corner : {a1, b0})
      if (corner > cuts[0] && corner < cuts[1]) cuts.push_back(corner);
    std::sort(cuts.begin(), cuts.end());
    std::vector<std::pair<int64_t, int64_t>> out;
    for (size_t i = 1; i < cuts.size(); ++i)
      if (cuts[i] > cuts[i - 1]) out.push_back({cuts[i - 1], cuts[i]});
    return out;
  }
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
    // The difference of two mean velocities is the acceleration weighed by a kernel that
    // rises over the first baseline, is 1 between them and falls over the last
    // (AccelerationKernel): the accelerometer is averaged with those weights, which is exact
    // for any motion, where a plain mean between the baselines' middles is off by a / 8 x
    // baseline wherever the acceleration steps (a car turning into a bend).
    const AccelerationKernel kernel{path_stamps_ns[a0], path_stamps_ns[a1], path_stamps_ns[b0],
                                    path_stamps_ns[b1]};
    // The samples over the kernel, and one on either side to reach its ends.
    const auto after_start =
        std::upper_bound(samples.begin(), samples.end(), kernel.a0,
                         [](int64_t t, const ImuSample& s) { return t < s.stamp_ns; });
    const auto end_sample = std::lower_bound(after_start, samples.end(), kernel.b1, by_stamp);
    if (after_start == samples.begin() || end_sample == samples.end()) continue;
    const auto first = std::prev(after_start);
    const auto last = std::next(end_sample);
    const auto n = static_cast<size_t>(std::distance(after_start, end_sample));
    if (n < 10 || 2 * n < wanted || first->stamp_ns < kernel.a0 - 2 * period_ns ||
        end_sample->stamp_ns > kernel.b1 + 2 * period_ns)
      continue;
    const Eigen::Matrix3d R_k_map = path_at(keyframe_stamps_ns[k]).rotation().transpose();
    GravityObservation o;
    o.node = k;
    o.samples = n;
    // Between two samples the force and the rotation change linearly (a sample is a reading
    // at its instant, not a period's) and the kernel is linear between its corners: their
    // product, a quadratic, is integrated exactly by Simpson's rule on each piece.
    o.mean_force.setZero();
    o.bias_rotation.setZero();
    Eigen::Matrix3d R_previous = R_k_map * path_at(first->stamp_ns).rotation();
    for (auto s = first, next = std::next(first); next != last; s = next, ++next) {
      const Eigen::Matrix3d R_next = R_k_map * path_at(next->stamp_ns).rotation();
      const int64_t t0 = s->stamp_ns, t1 = next->stamp_ns;
      const Eigen::Vector3d force0 = R_previous * s->accel_mps2;
      const Eigen::Vector3d force1 = R_next * next->accel_mps2;
      const auto linear = [&](double t, const auto& a, const auto& b) {
        const double f = (t - seconds(t0)) / seconds(t1 - t0);
        return ((1.0 - f) * a + f * b).eval();
      };
      for (const auto& [u, w] : kernel.pieces(t0, t1)) {
        const double p0 = seconds(u), p1 = seconds(w), middle = 0.5 * (p0 + p1);
        const double width = (p1 - p0) / 6.0;
        const double w0 = kernel.weight(p0), wm = kernel.weight(middle), w1 = kernel.weight(p1);
        o.mean_force +=
            width * (w0 * linear(p0, force0, force1) + 4.0 * wm * linear(middle, force0, force1) +
                     w1 * linear(p1, force0, force1));
        o.bias_rotation += width * (w0 * linear(p0, R_previous, R_next) +
                                    4.0 * wm * linear(middle, R_previous, R_next) +
                                    w1 * linear(p1, R_previous, R_next));
      }
      R_previous = R_next;
    }
    const int64_t start = v_start.at_ns;
    const int64_t end = v_end.at_ns;
    // The kernel's area: the time between the two means' middles.
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
