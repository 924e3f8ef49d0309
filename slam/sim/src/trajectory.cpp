#include "featsense/slam/sim/trajectory.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "featsense/slam/io/scan_writers.hpp"
#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {
namespace {

constexpr double kGravity = 9.81;  // m/s^2

/// Natural cubic spline through points at knots u (chord length), C2 everywhere.
class CubicSpline {
 public:
  explicit CubicSpline(const std::vector<Eigen::Vector3d>& points) : p_(points) {
    const size_t n = p_.size();
    u_.assign(n, 0.0);
    for (size_t i = 1; i < n; ++i) {
      const double h = (p_[i] - p_[i - 1]).norm();
      if (!(h > 1e-9))
        throw std::invalid_argument("trajectory: waypoints " + std::to_string(i - 1) + " and " +
                                    std::to_string(i) + " coincide");
      u_[i] = u_[i - 1] + h;
    }
    // Second derivatives M: tridiagonal system with M_0 = M_{n-1} = 0 (natural ends),
    // solved by the Thomas algorithm.
    m_.assign(n, Eigen::Vector3d::Zero());
    if (n < 3) return;
    std::vector<double> c(n, 0.0);
    std::vector<Eigen::Vector3d> d(n, Eigen::Vector3d::Zero());
    for (size_t i = 1; i + 1 < n; ++i) {
      const double h0 = u_[i] - u_[i - 1];
      const double h1 = u_[i + 1] - u_[i];
      const double a = h0 / 6.0;
      const double b = (h0 + h1) / 3.0 - a * c[i - 1];
      c[i] = (h1 / 6.0) / b;
      const Eigen::Vector3d rhs = (p_[i + 1] - p_[i]) / h1 - (p_[i] - p_[i - 1]) / h0;
      d[i] = (rhs - a * d[i - 1]) / b;
    }
    for (size_t i = n - 2; i >= 1; --i) m_[i] = d[i] - c[i] * m_[i + 1];
  }

  double length_param() const { return u_.back(); }
  const std::vector<double>& knots() const { return u_; }

  size_t interval(double u) const {
    const auto it = std::upper_bound(u_.begin(), u_.end(), u);
    const size_t i = it == u_.begin() ? 0 : static_cast<size_t>(it - u_.begin()) - 1;
    return std::min(i, u_.size() - 2);
  }

  /// Position, first and second derivative with respect to u.
  void evaluate(double u, Eigen::Vector3d* p, Eigen::Vector3d* dp, Eigen::Vector3d* ddp) const {
    const size_t i = interval(u);
    const double h = u_[i + 1] - u_[i];
    const double a = (u_[i + 1] - u) / h;
    const double b = (u - u_[i]) / h;
    if (p)
      *p = a * p_[i] + b * p_[i + 1] +
           ((a * a * a - a) * m_[i] + (b * b * b - b) * m_[i + 1]) * (h * h / 6.0);
    if (dp)
      *dp = (p_[i + 1] - p_[i]) / h +
            (-(3.0 * a * a - 1.0) * m_[i] + (3.0 * b * b - 1.0) * m_[i + 1]) * (h / 6.0);
    if (ddp) *ddp = a * m_[i] + b * m_[i + 1];
  }

 private:
  std::vector<Eigen::Vector3d> p_;
  std::vector<double> u_;
  std::vector<Eigen::Vector3d> m_;
};

class SplinePoseCurve final : public PoseCurve {
 public:
  SplinePoseCurve(const std::vector<Eigen::Vector3d>& waypoints, double speed, bool tilt)
      : spline_(waypoints), speed_(speed), tilt_(tilt) {
    const std::vector<double>& u = spline_.knots();
    arc_.assign(u.size(), 0.0);
    for (size_t i = 1; i < u.size(); ++i) arc_[i] = arc_[i - 1] + arc_length(u[i - 1], u[i]);
  }

  double duration_s() const override { return arc_.back() / speed_; }

  Eigen::Isometry3d pose(double t_s) const override {
    const double u = param_at(std::clamp(t_s, 0.0, duration_s()) * speed_);
    Eigen::Vector3d p, dp, ddp;
    spline_.evaluate(u, &p, &dp, &ddp);
    const Eigen::Vector3d tangent = dp.normalized();
    const double yaw = std::atan2(tangent.y(), tangent.x());
    double roll = 0.0;
    double pitch = 0.0;
    if (tilt_) {
      // Acceleration at constant speed: speed^2 times the curvature vector.
      const Eigen::Vector3d curvature = (ddp - ddp.dot(tangent) * tangent) / dp.squaredNorm();
      const Eigen::Vector3d accel = speed_ * speed_ * curvature;
      const Eigen::Vector3d left(-std::sin(yaw), std::cos(yaw), 0.0);
      roll = -std::atan(accel.dot(left) / kGravity);                           // lean into the turn
      pitch = -std::atan2(tangent.z(), std::hypot(tangent.x(), tangent.y()));  // nose up
    }
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                  Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                  Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    T.translation() = p;
    return T;
  }

 private:
  /// Length of the curve between parameters u0 and u1 (Gauss-Legendre, 5 nodes on 8 pieces).
  double arc_length(double u0, double u1) const {
    static const std::array<double, 5> kX = {0.0, -0.5384693101056831, 0.5384693101056831,
                                             -0.9061798459386640, 0.9061798459386640};
    static const std::array<double, 5> kW = {0.5688888888888889, 0.4786286704993665,
                                             0.4786286704993665, 0.2369268850561891,
                                             0.2369268850561891};
    constexpr int kPieces = 8;
    double total = 0.0;
    const double step = (u1 - u0) / kPieces;
    for (int k = 0; k < kPieces; ++k) {
      const double mid = u0 + (k + 0.5) * step;
      for (size_t j = 0; j < kX.size(); ++j) {
        Eigen::Vector3d dp;
        spline_.evaluate(mid + 0.5 * step * kX[j], nullptr, &dp, nullptr);
        total += 0.5 * step * kW[j] * dp.norm();
      }
    }
    return total;
  }

  /// The spline parameter at arc length s (Newton's method within the knot interval).
  double param_at(double s) const {
    const auto it = std::upper_bound(arc_.begin(), arc_.end(), s);
    size_t i = it == arc_.begin() ? 0 : static_cast<size_t>(it - arc_.begin()) - 1;
    i = std::min(i, arc_.size() - 2);
    const std::vector<double>& knots = spline_.knots();
    const double lo = knots[i];
    const double hi = knots[i + 1];
    const double target = s - arc_[i];
    double u = lo + (hi - lo) * target / (arc_[i + 1] - arc_[i]);
    for (int iteration = 0; iteration < 20; ++iteration) {
      Eigen::Vector3d dp;
      spline_.evaluate(u, nullptr, &dp, nullptr);
      const double step = (arc_length(lo, u) - target) / dp.norm();
      u = std::clamp(u - step, lo, hi);
      if (std::abs(step) < 1e-12) break;
    }
    return u;
  }

  CubicSpline spline_;
  double speed_;
  bool tilt_;
  std::vector<double> arc_;  ///< arc length at each knot, metres
};

class SampledPoseCurve final : public PoseCurve {
 public:
  explicit SampledPoseCurve(std::vector<StampedPose> poses) : poses_(std::move(poses)) {
    const double t0 = poses_.front().t_s;
    for (StampedPose& p : poses_) p.t_s -= t0;
  }
  double duration_s() const override { return poses_.back().t_s; }
  Eigen::Isometry3d pose(double t_s) const override {
    const double t = std::clamp(t_s, 0.0, duration_s());
    const auto it = std::upper_bound(poses_.begin(), poses_.end(), t,
                                     [](double v, const StampedPose& p) { return v < p.t_s; });
    size_t i = it == poses_.begin() ? 0 : static_cast<size_t>(it - poses_.begin()) - 1;
    i = std::min(i, poses_.size() - 2);
    const StampedPose& a = poses_[i];
    const StampedPose& b = poses_[i + 1];
    const double f = (t - a.t_s) / (b.t_s - a.t_s);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = (1.0 - f) * a.T_map_sensor.translation() + f * b.T_map_sensor.translation();
    T.linear() = Eigen::Quaterniond(a.T_map_sensor.rotation())
                     .slerp(f, Eigen::Quaterniond(b.T_map_sensor.rotation()))
                     .toRotationMatrix();
    return T;
  }

 private:
  std::vector<StampedPose> poses_;
};

/// A path followed in warped time: its own time advances at a speed factor that falls from 1
/// to 0 over the ramp before the stand, stays 0 for the stand and rises back over the ramp.
class PausedPoseCurve final : public PoseCurve {
 public:
  PausedPoseCurve(std::unique_ptr<PoseCurve> path, double at_s, double for_s, double ramp_s)
      : path_(std::move(path)), at_s_(at_s), for_s_(for_s), ramp_s_(ramp_s) {}

  double duration_s() const override { return path_->duration_s() + for_s_ + ramp_s_; }

  Eigen::Isometry3d pose(double t_s) const override { return path_->pose(path_time(t_s)); }

  /// The path's own time at `t_s`: the integral of the speed factor.
  double path_time(double t_s) const {
    constexpr double kPi = 3.14159265358979323846;
    const double slow_from = at_s_ - ramp_s_;
    const double resume_at = at_s_ + for_s_;
    const double stood_at = at_s_ - 0.5 * ramp_s_;  // the path's time where it stands
    const double k = ramp_s_ / kPi;
    if (t_s <= slow_from) return t_s;
    if (t_s < at_s_) {
      const double u = t_s - slow_from;  // factor 0.5 (1 + cos(pi u / ramp))
      return slow_from + 0.5 * u + 0.5 * k * std::sin(u / k);
    }
    if (t_s <= resume_at) return stood_at;
    if (t_s < resume_at + ramp_s_) {
      const double u = t_s - resume_at;  // factor 0.5 (1 - cos(pi u / ramp))
      return stood_at + 0.5 * u - 0.5 * k * std::sin(u / k);
    }
    return t_s - for_s_ - ramp_s_;
  }

 private:
  std::unique_ptr<PoseCurve> path_;
  double at_s_;
  double for_s_;
  double ramp_s_;
};

}  // namespace

std::unique_ptr<PoseCurve> make_paused_trajectory(std::unique_ptr<PoseCurve> path, double at_s,
                                                  double for_s, double ramp_s) {
  if (path == nullptr) throw std::invalid_argument("a stop needs a path");
  if (!(ramp_s > 0.0) || !(for_s > 0.0))
    throw std::invalid_argument("a stop needs a time to stand and to slow down, both > 0 s");
  if (!(at_s >= ramp_s) || !(at_s - 0.5 * ramp_s < path->duration_s()))
    throw std::invalid_argument("a stop at " + std::to_string(at_s) +
                                " s lies outside the path (it slows down from " +
                                std::to_string(ramp_s) + " s before; the path lasts " +
                                std::to_string(path->duration_s()) + " s)");
  return std::make_unique<PausedPoseCurve>(std::move(path), at_s, for_s, ramp_s);
}

std::unique_ptr<PoseCurve> make_spline_trajectory(const std::vector<Eigen::Vector3d>& waypoints_m,
                                                  double speed_mps, bool tilt) {
  if (waypoints_m.size() < 2)
    throw std::invalid_argument("trajectory: a spline needs at least two waypoints");
  if (!(speed_mps > 0.0)) throw std::invalid_argument("trajectory: speed must be > 0 m/s");
  return std::make_unique<SplinePoseCurve>(waypoints_m, speed_mps, tilt);
}

std::unique_ptr<PoseCurve> make_sampled_trajectory(const std::vector<StampedPose>& poses) {
  if (poses.size() < 2) throw std::invalid_argument("trajectory: needs at least two poses");
  for (size_t i = 1; i < poses.size(); ++i) {
    if (!(poses[i].t_s > poses[i - 1].t_s))
      throw std::invalid_argument("trajectory: pose times must increase (pose " +
                                  std::to_string(i) + ")");
  }
  return std::make_unique<SampledPoseCurve>(poses);
}

std::vector<StampedPose> to_stamped_poses(const Trajectory& trajectory) {
  std::vector<StampedPose> poses;
  poses.reserve(trajectory.size());
  for (size_t i = 0; i < trajectory.size(); ++i) {
    StampedPose pose;
    pose.t_s = 1e-9 * static_cast<double>(trajectory.stamps_ns[i]);
    pose.T_map_sensor = trajectory.poses[i];
    poses.push_back(pose);
  }
  return poses;
}

Trajectory to_trajectory(const std::vector<StampedPose>& poses) {
  Trajectory trajectory;
  for (const StampedPose& pose : poses) {
    trajectory.push_back(std::llround(pose.t_s * 1e9), pose.T_map_sensor);
  }
  return trajectory;
}

}  // namespace featsense::slam
