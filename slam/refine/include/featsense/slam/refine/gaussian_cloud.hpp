#pragma once
/// Points with the covariance of their neighbourhood, as GICP registers them: the shape of
/// the surface around each point (flat along it, thin across it).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace featsense::slam::refine {

struct GaussianCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Matrix3d> covariances;  ///< one per point

  size_t size() const { return points.size(); }
};

/// Each point's covariance from its `neighbours` nearest points (itself included), made
/// plane-like as GICP does: the eigenvalues replaced by (1, 1, 1e-3) so that every surface
/// counts by its shape, not by how densely or noisily it was sampled. Points with fewer than
/// 3 finite neighbours, and non-finite points, are dropped.
/// `kept`, where given, receives the index in `points` of each point of the result. With
/// `every` > 1 only every such finite point is kept (its neighbours still found among all).
GaussianCloud with_covariances(const std::vector<Eigen::Vector3f>& points, int neighbours,
                               std::vector<uint32_t>* kept = nullptr, size_t every = 1);

/// |n . direction| for the normal n (the thinnest axis) of a covariance with_covariances made,
/// or one turned from it (R C R^T), and a unit `direction`: read off the covariance, whose
/// spread along its axes is known, without an eigen decomposition for each point.
double normal_alignment(const Eigen::Matrix3d& covariance, const Eigen::Vector3d& direction);

/// The cloud moved by T: points T p, covariances R C R^T.
GaussianCloud transformed(const GaussianCloud& cloud, const Eigen::Isometry3d& T);

}  // namespace featsense::slam::refine
