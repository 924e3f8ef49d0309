// Umeyama's closed-form least-squares similarity, with or without scale.

#include "featsense/slam/trajectory/umeyama.hpp"

#include <Eigen/SVD>

#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

Similarity umeyama(const std::vector<Eigen::Vector3d>& source,
                   const std::vector<Eigen::Vector3d>& target, bool with_scale) {
  if (source.size() != target.size()) {
    throw TrajectoryError("alignment needs as many source as target points");
  }
  if (source.size() < 3) {
    throw TrajectoryError("alignment needs at least 3 pose pairs, got " +
                          std::to_string(source.size()) + " (or use --align none)");
  }
  const double n = static_cast<double>(source.size());
  Eigen::Vector3d mean_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_t = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < source.size(); ++i) {
    mean_s += source[i];
    mean_t += target[i];
  }
  mean_s /= n;
  mean_t /= n;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  // Sigma_xy of Umeyama's eq. (38)
  double variance_s = 0.0;                               // sigma_x^2, eq. (36)
  for (size_t i = 0; i < source.size(); ++i) {
    const Eigen::Vector3d ds = source[i] - mean_s;
    covariance += (target[i] - mean_t) * ds.transpose();
    variance_s += ds.squaredNorm();
  }
  covariance /= n;
  variance_s /= n;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sigma = svd.singularValues();
  // Rank 1 or less: the points lie on a line (or coincide) and the rotation about it is free.
  if (sigma(1) <= 1e-12 * std::max(1.0, sigma(0))) {
    throw TrajectoryError(
        "alignment is undetermined: the positions lie on a line or coincide (use --align none)");
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) S(2, 2) = -1;
  Similarity result;
  result.T.linear() = svd.matrixU() * S * svd.matrixV().transpose();
  result.scale = with_scale ? (sigma.asDiagonal() * S).trace() / variance_s : 1.0;
  result.T.translation() = mean_t - result.scale * result.T.linear() * mean_s;
  return result;
}

}  // namespace featsense::slam
