#include "featsense/slam/loops/trajectory_correction.hpp"

#include <algorithm>
#include <stdexcept>

namespace featsense::slam::loops {

Eigen::Isometry3d interpolate_pose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                   double s) {
  const Eigen::Quaterniond qa(a.rotation());
  const Eigen::Quaterniond qb(b.rotation());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = qa.slerp(s, qb).normalized().toRotationMatrix();
  out.translation() = (1.0 - s) * a.translation() + s * b.translation();
  return out;
}

void TrajectoryCorrection::add_keyframe(double travelled_m, const Eigen::Isometry3d& before,
                                        const Eigen::Isometry3d& after) {
  if (!travelled_m_.empty() && travelled_m < travelled_m_.back())
    throw std::invalid_argument("trajectory correction: keyframes must come in path order");
  travelled_m_.push_back(travelled_m);
  corrections_.push_back(after * before.inverse());
}

Eigen::Isometry3d TrajectoryCorrection::correction_at(double travelled_m) const {
  if (travelled_m_.empty()) return Eigen::Isometry3d::Identity();
  if (travelled_m <= travelled_m_.front()) return corrections_.front();
  if (travelled_m >= travelled_m_.back()) return corrections_.back();
  const size_t next =
      static_cast<size_t>(std::upper_bound(travelled_m_.begin(), travelled_m_.end(), travelled_m) -
                          travelled_m_.begin());
  const size_t previous = next - 1;
  const double span = travelled_m_[next] - travelled_m_[previous];
  const double s = span > 0.0 ? (travelled_m - travelled_m_[previous]) / span : 1.0;
  return interpolate_pose(corrections_[previous], corrections_[next], s);
}

}  // namespace featsense::slam::loops
