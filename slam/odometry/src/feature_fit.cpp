#include "featsense/slam/odometry/feature_fit.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>

namespace featsense::slam::odometry {
namespace {

struct Spread {
  Eigen::Vector3d centroid;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;  ///< eigenvalues ascending
};

Spread spread_of(const std::vector<Eigen::Vector3d>& points) {
  Spread s;
  s.centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) s.centroid += p;
  s.centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d d = p - s.centroid;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(points.size());
  s.eigen.computeDirect(covariance);
  return s;
}

}  // namespace

std::optional<FittedLine> fit_line(const std::vector<Eigen::Vector3d>& neighbours) {
  if (neighbours.size() < 2) return std::nullopt;
  const Spread s = spread_of(neighbours);
  const Eigen::Vector3d lambda = s.eigen.eigenvalues();
  if (!(lambda(2) > 3.0 * lambda(1)) || !(lambda(2) > 0.0)) return std::nullopt;
  FittedLine line{s.centroid, s.eigen.eigenvectors().col(2).normalized()};
  if (!line.direction.allFinite()) return std::nullopt;
  return line;
}

std::optional<FittedPlane> fit_plane(const std::vector<Eigen::Vector3d>& neighbours,
                                     double max_offset_m) {
  if (neighbours.size() < 3) return std::nullopt;
  const Spread s = spread_of(neighbours);
  const Eigen::Vector3d lambda = s.eigen.eigenvalues();
  if (!(lambda(0) * 3.0 < lambda(1)) || !(lambda(1) > 1e-3 * lambda(2))) return std::nullopt;
  FittedPlane plane;
  plane.normal = s.eigen.eigenvectors().col(0).normalized();
  plane.offset = -plane.normal.dot(s.centroid);
  if (!plane.normal.allFinite()) return std::nullopt;
  for (const Eigen::Vector3d& p : neighbours) {
    if (std::abs(plane.normal.dot(p) + plane.offset) > max_offset_m) return std::nullopt;
  }
  return plane;
}

}  // namespace featsense::slam::odometry
