#pragma once
/// The poses between keyframes after the pose graph moved the keyframes: each keyframe's
/// correction C = T_optimised * T_before^-1 (in the map frame), interpolated between the two
/// keyframes around a scan by the distance travelled, and applied to the scan's pose. Where
/// two keyframes agree the correction is constant; across the whole path it is continuous.

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace featsense::slam::loops {

class TrajectoryCorrection {
 public:
  /// A keyframe: where along the path it lies (metres travelled, increasing), its pose
  /// before and after the optimisation.
  void add_keyframe(double travelled_m, const Eigen::Isometry3d& before,
                    const Eigen::Isometry3d& after);

  /// The correction at `travelled_m`: the first keyframe's before it, the last's after it,
  /// identity without keyframes.
  Eigen::Isometry3d correction_at(double travelled_m) const;
  /// `pose` (taken at `travelled_m`) corrected.
  Eigen::Isometry3d apply(double travelled_m, const Eigen::Isometry3d& pose) const {
    return correction_at(travelled_m) * pose;
  }
  bool empty() const { return travelled_m_.empty(); }

 private:
  std::vector<double> travelled_m_;
  std::vector<Eigen::Isometry3d> corrections_;
};

/// `a` moved towards `b` by fraction s: rotation by slerp, translation linearly.
Eigen::Isometry3d interpolate_pose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b,
                                   double s);

}  // namespace featsense::slam::loops
