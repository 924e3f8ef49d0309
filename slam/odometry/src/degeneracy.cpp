#include "featsense/slam/odometry/degeneracy.hpp"

#include <Eigen/Eigenvalues>

namespace featsense::slam::odometry {

Degeneracy analyse_degeneracy(const Matrix6d& information, double threshold) {
  Degeneracy d;
  if (!information.allFinite()) {
    d.observable_projector.setZero();
    for (int i = 0; i < 6; ++i) d.unobservable.push_back(Vector6d::Unit(i));
    return d;
  }
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(0.5 *
                                                      (information + information.transpose()));
  d.eigenvalues = eigen.eigenvalues();
  d.eigenvectors = eigen.eigenvectors();
  for (int i = 0; i < 6; ++i) {
    if (d.eigenvalues(i) < threshold) {
      const Vector6d v = d.eigenvectors.col(i);
      d.unobservable.push_back(v);
      d.observable_projector -= v * v.transpose();
    }
  }
  return d;
}

}  // namespace featsense::slam::odometry
