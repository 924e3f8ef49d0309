#include "featsense/slam/odometry/stand_detector.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <vector>

#include "featsense/slam/odometry/pose_tangent.hpp"

namespace featsense::slam::odometry {
namespace {

/// A precision's eigenvalue below this fraction of its largest is a direction the
/// registration does not pin down: its variance is unbounded, not the inverse's huge number.
constexpr double kUnobservedFraction = 1e-9;

struct Split {
  Matrix6d covariance = Matrix6d::Zero();
  std::vector<Vector6d> unobserved;
};

/// The covariance of a precision over the directions it observes, and those it does not. A
/// zero precision gives no covariance and no unobserved direction.
Split split(const Matrix6d& precision) {
  Split out;
  if (precision.isZero(0.0)) return out;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(0.5 * (precision + precision.transpose()));
  const double largest = eigen.eigenvalues().maxCoeff();
  for (int i = 0; i < 6; ++i) {
    const double value = eigen.eigenvalues()(i);
    const Vector6d v = eigen.eigenvectors().col(i);
    if (!(value > kUnobservedFraction * largest)) {
      out.unobserved.push_back(v);
    } else {
      out.covariance += v * v.transpose() / value;
    }
  }
  return out;
}

}  // namespace

double chi_squared_999(int dimensions) {
  static constexpr std::array<double, 7> kQuantile{0.0,    10.828, 13.816, 16.266,
                                                   18.467, 20.515, 22.458};
  return kQuantile[static_cast<size_t>(std::clamp(dimensions, 0, 6))];
}

double mahalanobis_step(const Eigen::Isometry3d& from, const Matrix6d& from_precision,
                        const Eigen::Isometry3d& to, const Matrix6d& to_precision,
                        int* dimensions) {
  // A zero precision is the first scan's: its pose defines the map exactly, but the map holds
  // its points with their noise, so a registration to it is as uncertain as one between two
  // registered scans.
  const Split b = split(to_precision);
  const Split a = from_precision.isZero(0.0) ? b : split(from_precision);
  // The directions either leaves unobserved are dropped: project onto the rest.
  Matrix6d keep = Matrix6d::Identity();
  std::vector<Vector6d> unobserved = a.unobserved;
  unobserved.insert(unobserved.end(), b.unobserved.begin(), b.unobserved.end());
  if (!unobserved.empty()) {
    Eigen::Matrix<double, 6, Eigen::Dynamic> basis(6, static_cast<Eigen::Index>(unobserved.size()));
    for (size_t i = 0; i < unobserved.size(); ++i)
      basis.col(static_cast<Eigen::Index>(i)) = unobserved[i];
    const Eigen::JacobiSVD<Eigen::Matrix<double, 6, Eigen::Dynamic>> svd(basis,
                                                                         Eigen::ComputeThinU);
    for (Eigen::Index i = 0; i < svd.singularValues().size(); ++i) {
      if (svd.singularValues()(i) > 1e-6)
        keep -= svd.matrixU().col(i) * svd.matrixU().col(i).transpose();
    }
  }
  const Matrix6d covariance = keep * (a.covariance + b.covariance) * keep;
  const Vector6d step = keep * tangent_between(from, to);
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(0.5 * (covariance + covariance.transpose()));
  const double largest = std::max(eigen.eigenvalues().maxCoeff(), 0.0);
  double distance2 = 0.0;
  int counted = 0;
  for (int i = 0; i < 6; ++i) {
    const double variance = eigen.eigenvalues()(i);
    if (!(variance > kUnobservedFraction * largest) || largest <= 0.0) continue;
    const double along = eigen.eigenvectors().col(i).dot(step);
    distance2 += along * along / variance;
    ++counted;
  }
  if (dimensions != nullptr) *dimensions = counted;
  return distance2;
}

StandDetector::StandDetector(int enter_scans, int leave_scans)
    : enter_scans_(std::max(enter_scans, 1)), leave_scans_(std::max(leave_scans, 1)) {}

StandDetector::Verdict StandDetector::update(const Eigen::Isometry3d& previous,
                                             const Matrix6d& previous_precision,
                                             const Eigen::Isometry3d& registered,
                                             const Matrix6d& precision, bool registered_ok) {
  Verdict verdict;
  verdict.pose = registered;
  const auto within_noise = [](const Eigen::Isometry3d& from, const Matrix6d& from_precision,
                               const Eigen::Isometry3d& to, const Matrix6d& to_precision) {
    int dimensions = 0;
    const double distance2 = mahalanobis_step(from, from_precision, to, to_precision, &dimensions);
    return dimensions > 0 && distance2 <= chi_squared_999(dimensions);
  };

  if (standing_) {
    if (!registered_ok || within_noise(anchor_, anchor_precision_, registered, precision)) {
      out_ = 0;
    } else if (++out_ >= leave_scans_) {
      // Moving again: the registration against the map as the stand left it.
      standing_ = false;
      out_ = 0;
      still_ = 0;
      verdict.resumed = true;
      return verdict;
    }
    verdict.standing = true;
    verdict.pose = anchor_;
    return verdict;
  }

  if (!registered_ok || !within_noise(previous, previous_precision, registered, precision)) {
    still_ = 0;
    return verdict;
  }
  if (still_ == 0) {
    run_start_ = previous;
    run_start_precision_ = previous_precision;
  }
  if (++still_ >= enter_scans_) {
    standing_ = true;
    out_ = 0;
    anchor_ = run_start_;
    anchor_precision_ = run_start_precision_;
    verdict.standing = true;
    verdict.pose = anchor_;
  }
  return verdict;
}

}  // namespace featsense::slam::odometry
