#include "featsense/slam/trajectory/pose_interpolation.hpp"

#include <algorithm>
#include <cmath>

namespace featsense::slam {

Eigen::Isometry3d interpolate_pose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                   double f) {
  const Eigen::Quaterniond qa(a.linear());
  Eigen::Quaterniond qb(b.linear());
  if (qa.dot(qb) < 0.0) qb.coeffs() = -qb.coeffs();  // the short way round
  Eigen::Quaterniond q;
  if (f >= 0.0 && f <= 1.0) {
    q = qa.slerp(f, qb);
  } else {
    // Beyond the ends: the relative rotation, scaled as an angle about its axis.
    const Eigen::AngleAxisd step(qa.conjugate() * qb);
    q = qa * Eigen::Quaterniond(Eigen::AngleAxisd(step.angle() * f, step.axis()));
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = a.translation() + f * (b.translation() - a.translation());
  return pose;
}

PoseInterpolator::PoseInterpolator(Trajectory trajectory, double max_extrapolation_s)
    : trajectory_(std::move(trajectory)),
      max_extrapolation_ns_(static_cast<int64_t>(std::llround(max_extrapolation_s * 1e9))) {
  if (trajectory_.empty()) throw TrajectoryError("the trajectory holds no pose");
  if (!trajectory_.has_stamps) {
    throw TrajectoryError("the trajectory has no time stamps (KITTI without a times file)");
  }
}

std::optional<Eigen::Isometry3d> PoseInterpolator::at(int64_t stamp_ns) const {
  const std::vector<int64_t>& stamps = trajectory_.stamps_ns;
  const std::vector<Eigen::Isometry3d>& poses = trajectory_.poses;
  if (stamp_ns < stamps.front() - max_extrapolation_ns_ ||
      stamp_ns > stamps.back() + max_extrapolation_ns_) {
    return std::nullopt;
  }
  if (stamps.size() == 1) return poses.front();
  // The pair of poses around the stamp (the first or last pair beyond the ends).
  const auto upper = std::upper_bound(stamps.begin(), stamps.end(), stamp_ns);
  size_t i = static_cast<size_t>(std::clamp<std::ptrdiff_t>(
      upper - stamps.begin(), 1, static_cast<std::ptrdiff_t>(stamps.size()) - 1));
  const int64_t t0 = stamps[i - 1];
  const int64_t t1 = stamps[i];
  if (stamp_ns == t1) return poses[i];
  const double f = static_cast<double>(stamp_ns - t0) / static_cast<double>(t1 - t0);
  return interpolate_pose(poses[i - 1], poses[i], f);
}

Eigen::Isometry3d motion_fraction(const Eigen::Isometry3d& motion, double s) {
  return interpolate_pose(Eigen::Isometry3d::Identity(), motion, s);
}

}  // namespace featsense::slam
