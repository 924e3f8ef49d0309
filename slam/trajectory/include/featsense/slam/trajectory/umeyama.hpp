#pragma once
/// Least-squares similarity between two point sets (Umeyama 1991, "Least-squares estimation
/// of transformation parameters between two point patterns"): target ~ scale * R * source + t.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace featsense::slam {

struct Similarity {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();  ///< rotation and translation, metres
  double scale = 1.0;

  /// scale * R * p + t
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const {
    return scale * (T.linear() * p) + T.translation();
  }
};

/// The similarity (with_scale) or rigid transform (scale fixed to 1) that maps `source` onto
/// `target` with the least sum of squared distances. Throws TrajectoryError for fewer than 3
/// points, different counts, or points on one line (rotation about it undetermined).
Similarity umeyama(const std::vector<Eigen::Vector3d>& source,
                   const std::vector<Eigen::Vector3d>& target, bool with_scale);

}  // namespace featsense::slam
