#include <Eigen/Cholesky>
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <vector>

#include "featsense/slam/loops/gravity_reference.hpp"
#include "robust_spread.hpp"

namespace featsense::slam::loops {
namespace {

/// Fewer observations than this tell too little about their scatter: left as modelled.
constexpr size_t kMinObservationsToWeigh = 10;

}  // namespace

GravityAgreement weigh_gravity_against_lidar(std::vector<GravityObservation>* observations,
                                             const std::vector<Eigen::Matrix3d>& R_map_node,
                                             double bias_prior_mps2) {
  GravityAgreement agreement;
  const size_t n = observations->size();
  if (n < kMinObservationsToWeigh || !(bias_prior_mps2 > 0.0)) return agreement;
  for (const GravityObservation& o : *observations)
    if (o.node >= R_map_node.size() || !(o.up().norm() > 0.0)) return agreement;
  // Each observation's up turned into the map frame by its node's rotation, horizontal part
  // x_i; it is linear in a common tilt t (about x and y, small) and the bias b:
  //   x_i + (t_y, -t_x) - [R_i B_i b]_xy / |up_i| = e_i,
  // weighted by one window's modelled error. Solved with the bias's prior.
  std::vector<double> window_sigma(n);
  Eigen::Matrix<double, 5, 5> normal = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> rhs = Eigen::Matrix<double, 5, 1>::Zero();
  normal.bottomRightCorner<3, 3>() =
      Eigen::Matrix3d::Identity() / (bias_prior_mps2 * bias_prior_mps2);
  std::vector<Eigen::Matrix<double, 2, 5>> jacobians(n);
  std::vector<Eigen::Vector2d> horizontal(n);
  for (size_t i = 0; i < n; ++i) {
    const GravityObservation& o = (*observations)[i];
    window_sigma[i] = o.sigma_rad / std::sqrt(std::max(1.0, o.shared));
    const Eigen::Matrix3d& R = R_map_node[o.node];
    const double length = o.up().norm();
    horizontal[i] = (R * o.up()).head<2>() / length;
    Eigen::Matrix<double, 2, 5> J;
    J.block<2, 2>(0, 0) << 0.0, 1.0, -1.0, 0.0;
    J.block<2, 3>(0, 2) = -(R * o.bias_rotation).topRows<2>() / length;
    jacobians[i] = J;
    const double w = 1.0 / (window_sigma[i] * window_sigma[i]);
    normal += w * J.transpose() * J;
    rhs -= w * J.transpose() * horizontal[i];
  }
  const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> solver(normal);
  if (solver.info() != Eigen::Success) return agreement;
  const Eigen::Matrix<double, 5, 1> fit = solver.solve(rhs);
  if (!fit.allFinite()) return agreement;
  // The scatter about the fit: a robust variance pooled over both axes (a jolt or two do not
  // count).
  std::vector<double> squares;
  squares.reserve(2 * n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d e = horizontal[i] + jacobians[i] * fit;
    squares.push_back(e.x() * e.x());
    squares.push_back(e.y() * e.y());
  }
  agreement.observations = n;
  agreement.scatter_rad = std::sqrt(robust_variance(squares));
  std::vector<double> sorted_sigma = window_sigma;
  agreement.model_rad = upper_median(sorted_sigma);
  for (size_t i = 0; i < n; ++i) {
    GravityObservation& o = (*observations)[i];
    o.sigma_rad =
        std::max(window_sigma[i], agreement.scatter_rad) * std::sqrt(std::max(1.0, o.shared));
  }
  return agreement;
}

}  // namespace featsense::slam::loops
