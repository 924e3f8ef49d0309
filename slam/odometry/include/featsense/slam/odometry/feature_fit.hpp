#pragma once
/// Lines and planes through a scan point's nearest map points: the correspondences.

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace featsense::slam::odometry {

struct FittedLine {
  Eigen::Vector3d point;      ///< the neighbours' centroid
  Eigen::Vector3d direction;  ///< unit
};

struct FittedPlane {
  Eigen::Vector3d normal;  ///< unit
  double offset = 0.0;     ///< n . x + offset = 0
};

/// A line when the neighbours' covariance has a largest eigenvalue above 3 times the second
/// (as LOAM / F-LOAM); nullopt otherwise or for fewer than 2 points.
std::optional<FittedLine> fit_line(const std::vector<Eigen::Vector3d>& neighbours);

/// A plane when the smallest eigenvalue of the covariance is below a third of the middle
/// one and the points do not lie on a line (middle above 1e-3 of the largest), and no
/// neighbour is farther than `max_offset_m` (F-LOAM: 0.2 m) from it; nullopt otherwise or
/// for fewer than 3 points.
std::optional<FittedPlane> fit_plane(const std::vector<Eigen::Vector3d>& neighbours,
                                     double max_offset_m = 0.2);

}  // namespace featsense::slam::odometry
