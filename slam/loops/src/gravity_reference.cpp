#include "featsense/slam/loops/gravity_reference.hpp"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <utility>
#include <vector>

#include "featsense/slam/loops/trajectory_correction.hpp"
#include "featsense/slam/upper_median.hpp"

namespace featsense::slam::loops {
namespace {

double seconds(int64_t ns) { return static_cast<double>(ns) * 1e-9; }

/// Fewer positions than this in a window give no observation: a quadratic through three
/// leaves nothing to average.
constexpr size_t kMinPositions = 6;

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

/// The path's acceleration over a window, as the odometry measures it: the second-order
/// coefficient of a least-squares quadratic through every position in the window,
/// a = sum_j w_j p_j. The weights cancel a constant and a linear term and have unit response
/// to t^2 / 2, so for any motion sum_j w_j p_j = int a(s) K(s) ds with the kernel
/// K(s) = sum_j w_j (t_j - s)_+, linear between stamps and of unit integral: the accelerometer
/// averaged with K is exactly what the positions measure. Each position's error enters with
/// its weight only, where a difference of two mean velocities at the window's ends rests on
/// four positions (at 5 mm each, ten times the error over 4 s).
class QuadraticFitKernel {
 public:
  /// Positions [first, last] of the path's stamps; at least four.
  QuadraticFitKernel(const std::vector<int64_t>& stamps_ns, size_t first, size_t last)
      : stamps_(stamps_ns.begin() + static_cast<std::ptrdiff_t>(first),
                stamps_ns.begin() + static_cast<std::ptrdiff_t>(last) + 1) {
    const size_t n = stamps_.size();
    const int64_t middle = stamps_.front() + (stamps_.back() - stamps_.front()) / 2;
    Eigen::MatrixXd design(static_cast<Eigen::Index>(n), 3);
    for (size_t j = 0; j < n; ++j) {
      const double t = seconds(stamps_[j] - middle);
      design.row(static_cast<Eigen::Index>(j)) << 1.0, t, 0.5 * t * t;
    }
    // The third row of the pseudo-inverse, A (A^T A)^-1 e_3 (centred times: well conditioned).
    const Eigen::Vector3d row =
        (design.transpose() * design).ldlt().solve(Eigen::Vector3d::UnitZ());
    const Eigen::VectorXd weights = design * row;
    weights_.assign(weights.data(), weights.data() + weights.size());
    // K at each stamp: sum over the later stamps of w_j (t_j - t_m).
    at_stamps_.assign(n, 0.0);
    for (size_t m = 0; m < n; ++m)
      for (size_t j = m + 1; j < n; ++j)
        at_stamps_[m] += weights_[j] * seconds(stamps_[j] - stamps_[m]);
  }

  const std::vector<double>& weights() const { return weights_; }
  int64_t begin_ns() const { return stamps_.front(); }
  int64_t end_ns() const { return stamps_.back(); }

  /// K(t), linear between stamps, zero outside them.
  double weight(int64_t t_ns) const {
    if (t_ns < stamps_.front() || t_ns > stamps_.back()) return 0.0;
    const auto after = std::lower_bound(stamps_.begin(), stamps_.end(), t_ns);
    const auto m = static_cast<size_t>(std::distance(stamps_.begin(), after));
    if (m == 0 || stamps_[m] == t_ns) return at_stamps_[m];
    const double f = static_cast<double>(t_ns - stamps_[m - 1]) /
                     static_cast<double>(stamps_[m] - stamps_[m - 1]);
    return (1.0 - f) * at_stamps_[m - 1] + f * at_stamps_[m];
  }

  /// int K^2 dt (exact for the linear pieces): the accelerometer's white noise enters the
  /// weighted mean as noise^2 x period x this.
  double squared_integral() const {
    double sum = 0.0;
    for (size_t m = 1; m < stamps_.size(); ++m) {
      const double a = at_stamps_[m - 1], b = at_stamps_[m];
      sum += seconds(stamps_[m] - stamps_[m - 1]) * (a * a + a * b + b * b) / 3.0;
    }
    return sum;
  }

  /// [t0, t1] clipped to the kernel and cut at its stamps: pieces on which it is linear.
  std::vector<std::pair<int64_t, int64_t>> pieces(int64_t t0, int64_t t1) const {
    std::vector<std::pair<int64_t, int64_t>> out;
    int64_t from = std::max(t0, stamps_.front());
    const int64_t to = std::min(t1, stamps_.back());
    if (to <= from) return out;
    for (auto corner = std::upper_bound(stamps_.begin(), stamps_.end(), from);
         corner != stamps_.end() && *corner < to; ++corner) {
      out.push_back({from, *corner});
      from = *corner;
    }
    out.push_back({from, to});
    return out;
  }

 private:
  std::vector<int64_t> stamps_;
  std::vector<double> weights_;
  std::vector<double> at_stamps_;
};

}  // namespace

int64_t median_sample_period_ns(const std::vector<ImuSample>& samples) {
  if (samples.size() < 2) return 0;
  std::vector<int64_t> spacing;
  for (size_t i = 1; i < samples.size(); ++i)
    spacing.push_back(samples[i].stamp_ns - samples[i - 1].stamp_ns);
  return upper_median(spacing);
}

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
  const int64_t period_ns = median_sample_period_ns(samples);
  if (period_ns <= 0) return out;
  const auto window_ns = static_cast<int64_t>(settings.window_s * 1e9);
  const auto wanted = static_cast<size_t>(settings.window_s / seconds(period_ns));

  const PathAt path_at(path_stamps_ns, path);
  const auto by_stamp = [](const ImuSample& s, int64_t t) { return s.stamp_ns < t; };
  for (size_t k = 0; k < keyframe_stamps_ns.size(); ++k) {
    // The window around the keyframe, slid to stay within the path: the positions in it.
    int64_t from = keyframe_stamps_ns[k] - window_ns / 2;
    from = std::max(path_stamps_ns.front(), std::min(from, path_stamps_ns.back() - window_ns));
    const size_t first_position = path_at.at_or_after(from);
    const size_t end_position = path_at.at_or_after(from + window_ns + 1);
    if (end_position < first_position + kMinPositions) continue;
    const size_t last_position = end_position - 1;
    // Half the window at least: a path shorter than that tells too little.
    if (2 * (path_stamps_ns[last_position] - path_stamps_ns[first_position]) < window_ns) continue;
    const QuadraticFitKernel kernel(path_stamps_ns, first_position, last_position);
    // The samples over the kernel, and one on either side to reach its ends.
    const auto after_start =
        std::upper_bound(samples.begin(), samples.end(), kernel.begin_ns(),
                         [](int64_t t, const ImuSample& s) { return t < s.stamp_ns; });
    const auto end_sample = std::lower_bound(after_start, samples.end(), kernel.end_ns(), by_stamp);
    if (after_start == samples.begin() || end_sample == samples.end()) continue;
    const auto first = std::prev(after_start);
    const auto last = std::next(end_sample);
    const auto n = static_cast<size_t>(std::distance(after_start, end_sample));
    if (n < 10 || 2 * n < wanted || first->stamp_ns < kernel.begin_ns() - 2 * period_ns ||
        end_sample->stamp_ns > kernel.end_ns() + 2 * period_ns)
      continue;
    const Eigen::Matrix3d R_k_map = path_at(keyframe_stamps_ns[k]).rotation().transpose();
    GravityObservation o;
    o.node = k;
    o.samples = n;
    // Between two samples the force and the rotation change linearly (a sample is a reading
    // at its instant, not a period's) and the kernel is linear between stamps: their product,
    // a quadratic, is integrated exactly by Simpson's rule on each piece. The kernel's
    // integral is one: this is a weighted mean.
    o.mean_force.setZero();
    o.bias_rotation.setZero();
    Eigen::Matrix3d R_previous = R_k_map * path_at(first->stamp_ns).rotation();
    for (auto s = first, next = std::next(first); next != last; s = next, ++next) {
      const Eigen::Matrix3d R_next = R_k_map * path_at(next->stamp_ns).rotation();
      const int64_t t0 = s->stamp_ns, t1 = next->stamp_ns;
      const Eigen::Vector3d force0 = R_previous * s->accel_mps2;
      const Eigen::Vector3d force1 = R_next * next->accel_mps2;
      const auto linear = [&](int64_t t, const auto& a, const auto& b) {
        const double f = static_cast<double>(t - t0) / static_cast<double>(t1 - t0);
        return ((1.0 - f) * a + f * b).eval();
      };
      for (const auto& [u, w] : kernel.pieces(t0, t1)) {
        const int64_t middle = u + (w - u) / 2;
        const double width = seconds(w - u) / 6.0;
        const double w0 = kernel.weight(u), wm = kernel.weight(middle), w1 = kernel.weight(w);
        o.mean_force +=
            width * (w0 * linear(u, force0, force1) + 4.0 * wm * linear(middle, force0, force1) +
                     w1 * linear(w, force0, force1));
        o.bias_rotation += width * (w0 * linear(u, R_previous, R_next) +
                                    4.0 * wm * linear(middle, R_previous, R_next) +
                                    w1 * linear(w, R_previous, R_next));
      }
      R_previous = R_next;
    }
    Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
    for (size_t j = 0; j < kernel.weights().size(); ++j)
      acceleration += kernel.weights()[j] * path[first_position + j].translation();
    o.path_acceleration = R_k_map * acceleration;
    // The noise of the mean force (white per sample), of the positions' fit, the odometry's
    // share of its acceleration and the floor, as an angle; the windows of the keyframes
    // around share their samples, so each counts for a share.
    double squared_weights = 0.0;
    for (const double w : kernel.weights()) squared_weights += w * w;
    const double accel =
        settings.accel_noise_mps2 * std::sqrt(seconds(period_ns) * kernel.squared_integral());
    const double positions = settings.position_sigma_m * std::sqrt(squared_weights);
    const double up = std::max(o.up().norm(), 1.0);
    const auto shared = static_cast<double>(
        std::upper_bound(keyframe_stamps_ns.begin(), keyframe_stamps_ns.end(), kernel.end_ns()) -
        std::lower_bound(keyframe_stamps_ns.begin(), keyframe_stamps_ns.end(), kernel.begin_ns()));
    o.shared = std::max(1.0, shared);
    const double odometry = settings.odometry_acceleration_error * o.path_acceleration.norm();
    o.sigma_rad = std::sqrt(accel * accel + positions * positions + odometry * odometry +
                            settings.min_sigma_mps2 * settings.min_sigma_mps2) /
                  up * std::sqrt(o.shared);
    out.push_back(o);
  }
  return out;
}

}  // namespace featsense::slam::loops
