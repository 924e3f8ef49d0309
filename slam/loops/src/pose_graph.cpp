#include "featsense/slam/loops/pose_graph.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

namespace featsense::slam::loops {
namespace {

/// An edge's whitened error: sqrt(I) times the error of PoseGraphEdge, for Ceres' automatic
/// derivatives. Poses are a translation and a unit quaternion (Eigen's x y z w order).
class RelativePoseCost {
 public:
  RelativePoseCost(const Eigen::Isometry3d& T_from_to, const Matrix6d& sqrt_information)
      : q_measured_(T_from_to.rotation()),
        t_measured_(T_from_to.translation()),
        sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* t_from, const T* q_from, const T* t_to, const T* q_to,
                  T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Vector3> p_from(t_from);
    const Eigen::Map<const Vector3> p_to(t_to);
    const Eigen::Map<const Eigen::Quaternion<T>> r_from(q_from);
    const Eigen::Map<const Eigen::Quaternion<T>> r_to(q_to);
    const Eigen::Quaternion<T> r_estimated = r_from.conjugate() * r_to;
    const Vector3 t_estimated = r_from.conjugate() * (p_to - p_from);
    // R_est R_meas^T, and its angle-axis (the shorter way round).
    const Eigen::Quaternion<T> r_error = r_estimated * q_measured_.conjugate().template cast<T>();
    const T wxyz[4] = {r_error.w(), r_error.x(), r_error.y(), r_error.z()};
    Eigen::Matrix<T, 6, 1> error;
    ceres::QuaternionToAngleAxis(wxyz, error.data());
    error.template tail<3>() = t_estimated - r_error * t_measured_.template cast<T>();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> whitened(residual);
    whitened = sqrt_information_.template cast<T>() * error;
    return true;
  }

 private:
  Eigen::Quaterniond q_measured_;
  Eigen::Vector3d t_measured_;
  Matrix6d sqrt_information_;
};

/// Two directions across the mean up direction of the sensor frame: the accelerometer's bias
/// along up only changes gravity's length, which the observations do not use.
using BiasBasis = Eigen::Matrix<double, 3, 2>;

BiasBasis bias_basis(const std::vector<GravityObservation>& observations) {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  for (const GravityObservation& o : observations) up += o.up().normalized();
  up = up.norm() > 0.0 ? Eigen::Vector3d(up.normalized()) : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d helper =
      std::abs(up.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  BiasBasis basis;
  basis.col(0) = up.cross(helper).normalized();
  basis.col(1) = up.cross(basis.col(0));
  return basis;
}

/// A gravity observation's error: the node's up vector (the observation's, less the bias)
/// turned into the vertical frame (the map frame tilted back) should point along +Z; its x and
/// y components over its length, whitened, are the residual (radians for small tilts). The
/// length is the observation's without bias, a constant: divided by the vector's own length,
/// a bias along up would shorten every residual by lengthening the vector.
class GravityCost {
 public:
  /// The bias is bias_basis x (two coordinates): the part along up only scales the vector.
  GravityCost(const GravityObservation& observation, const BiasBasis& bias_basis)
      : o_(observation), basis_(bias_basis), length_(observation.up().norm()) {}

  template <typename T>
  bool operator()(const T* q_node, const T* map_tilt, const T* bias, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> r_node(q_node);
    const Vector3 b = basis_.template cast<T>() * Eigen::Map<const Eigen::Matrix<T, 2, 1>>(bias);
    const Vector3 up_node =
        (o_.mean_force.template cast<T>() - o_.bias_rotation.template cast<T>() * b -
         o_.path_acceleration.template cast<T>()) /
        length_;
    const Vector3 up_map = r_node * up_node;
    const T tilt[3] = {map_tilt[0], map_tilt[1], T(0)};
    T up_vertical[3];
    ceres::AngleAxisRotatePoint(tilt, up_map.data(), up_vertical);
    residual[0] = up_vertical[0] / o_.sigma_rad;
    residual[1] = up_vertical[1] / o_.sigma_rad;
    return true;
  }

 private:
  GravityObservation o_;
  BiasBasis basis_;
  double length_;
};

/// A weak prior, zero with `sigma` per component, on a bias of `Size` components: the
/// accelerometer's (for paths that never turn, it is unobservable from a tilt of the whole
/// map then) and the gyroscope's.
template <int Size>
class BiasPriorCost {
 public:
  explicit BiasPriorCost(double sigma) : sigma_(sigma) {}
  template <typename T>
  bool operator()(const T* bias, T* residual) const {
    for (int i = 0; i < Size; ++i) residual[i] = bias[i] / sigma_;
    return true;
  }

 private:
  double sigma_;
};

/// A gyroscope edge's error: the rotation the graph has between its nodes against the
/// gyroscope's, its bias taken out (delta Exp(-J b)), as an angle-axis over sigma.
class GyroCost {
 public:
  explicit GyroCost(const GyroObservation& observation)
      : delta_(Eigen::Quaterniond(observation.delta).normalized()),
        jacobian_(observation.bias_jacobian),
        sigma_(observation.sigma_rad) {}

  template <typename T>
  bool operator()(const T* q_from, const T* q_to, const T* bias, T* residual) const {
    using Vector3 = Eigen::Matrix<T, 3, 1>;
    const Eigen::Map<const Eigen::Quaternion<T>> r_from(q_from);
    const Eigen::Map<const Eigen::Quaternion<T>> r_to(q_to);
    const Vector3 correction = -(jacobian_.template cast<T>() * Eigen::Map<const Vector3>(bias));
    T correction_wxyz[4];
    ceres::AngleAxisToQuaternion(correction.data(), correction_wxyz);
    const Eigen::Quaternion<T> r_correction(correction_wxyz[0], correction_wxyz[1],
                                            correction_wxyz[2], correction_wxyz[3]);
    const Eigen::Quaternion<T> measured = delta_.template cast<T>() * r_correction;
    const Eigen::Quaternion<T> error = measured.conjugate() * (r_from.conjugate() * r_to);
    const T wxyz[4] = {error.w(), error.x(), error.y(), error.z()};
    ceres::QuaternionToAngleAxis(wxyz, residual);
    for (int i = 0; i < 3; ++i) residual[i] /= T(sigma_(i));
    return true;
  }

 private:
  Eigen::Quaterniond delta_;
  Eigen::Matrix3d jacobian_;
  Eigen::Vector3d sigma_;
};

constexpr double kDegreesPerRadian = 180.0 / 3.14159265358979323846;

/// What the gravity observations say at the solution, in one pass over them: the covariance
/// of the map frame's tilt from them alone, with the bias (its prior included) marginalised
/// (how well gravity tells the vertical, not what the first node's attitude says), and the
/// sum of their squared whitened residuals.
struct GravityFit {
  Eigen::Matrix2d tilt_covariance = Eigen::Matrix2d::Identity();
  double squared_residuals = 0.0;
};

GravityFit fit_gravity(const std::vector<GravityObservation>& observations, const BiasBasis& basis,
                       const std::vector<Eigen::Quaterniond>& rotations,
                       const Eigen::Vector2d& map_tilt, const Eigen::Vector2d& bias,
                       double bias_prior) {
  GravityFit fit;
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  information.bottomRightCorner<2, 2>() = Eigen::Matrix2d::Identity() / (bias_prior * bias_prior);
  for (const GravityObservation& o : observations) {
    ceres::AutoDiffCostFunction<GravityCost, 2, 4, 2, 2> cost(new GravityCost(o, basis));
    const double* parameters[3] = {rotations[o.node].coeffs().data(), map_tilt.data(), bias.data()};
    double residual[2];
    Eigen::Matrix<double, 2, 4, Eigen::RowMajor> d_rotation;
    Eigen::Matrix<double, 2, 2, Eigen::RowMajor> d_tilt, d_bias;
    double* jacobians[3] = {d_rotation.data(), d_tilt.data(), d_bias.data()};
    if (!cost.Evaluate(parameters, residual, jacobians)) continue;
    fit.squared_residuals += residual[0] * residual[0] + residual[1] * residual[1];
    Eigen::Matrix<double, 2, 4> J;
    J << d_tilt, d_bias;
    information += J.transpose() * J;
  }
  const Eigen::Matrix2d tilt = information.inverse().topLeftCorner<2, 2>();
  if (tilt.allFinite()) fit.tilt_covariance = tilt;
  return fit;
}

/// U with U^T U = information.
Matrix6d square_root(const Matrix6d& information) {
  const Eigen::LLT<Matrix6d> llt(information);
  if (llt.info() != Eigen::Success)
    throw std::invalid_argument("pose graph: an edge's information is not positive definite");
  return llt.matrixU();
}

/// The map frame tilted back by what the gravity observations of every node say, about the
/// first node (`first_position` stays), shrunk by the tilt's significance; fills `gravity`
/// (but its accel_bias_mps2) and leaves `map_tilt_rad` at zero: the poses are levelled, the
/// next solve starts from level.
Eigen::Isometry3d level_by_gravity(const std::vector<GravityObservation>& observations,
                                   const BiasBasis& basis,
                                   const std::vector<Eigen::Quaterniond>& rotations,
                                   const Eigen::Vector3d& first_position,
                                   const Eigen::Vector2d& bias_coordinates, double bias_prior_mps2,
                                   Eigen::Vector2d& map_tilt_rad, GravityEstimate& gravity) {
  const GravityFit fit =
      fit_gravity(observations, basis, rotations, map_tilt_rad, bias_coordinates, bias_prior_mps2);
  gravity.observations = observations.size();
  gravity.map_tilt_deg = map_tilt_rad * kDegreesPerRadian;
  gravity.rms_whitened =
      std::sqrt(fit.squared_residuals / (2.0 * static_cast<double>(observations.size())));
  gravity.tilt_sigma_deg =
      std::sqrt(std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(fit.tilt_covariance)
                                  .eigenvalues()
                                  .maxCoeff())) *
      kDegreesPerRadian;
  // An accelerometer's bias is told from a tilt only once the path turns: until then the
  // tilt found is as uncertain as the bias over g. Shrink it towards the first node's level
  // by its significance (none at one sigma, 89 % at three).
  const double significance2 = map_tilt_rad.dot(fit.tilt_covariance.inverse() * map_tilt_rad);
  const double shrink = significance2 > 1.0 ? 1.0 - 1.0 / significance2 : 0.0;
  gravity.levelled_deg = shrink * map_tilt_rad.norm() * kDegreesPerRadian;
  const Eigen::Vector3d axis(shrink * map_tilt_rad.x(), shrink * map_tilt_rad.y(), 0.0);
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  if (axis.norm() > 0.0) {
    level.linear() = Eigen::AngleAxisd(axis.norm(), axis.normalized()).toRotationMatrix();
    level.translation() = first_position - level.linear() * first_position;
  }
  map_tilt_rad.setZero();
  return level;
}

}  // namespace

Eigen::Matrix<double, 6, 1> edge_error(const Eigen::Isometry3d& T_map_from,
                                       const Eigen::Isometry3d& T_map_to,
                                       const Eigen::Isometry3d& T_from_to) {
  const Eigen::Isometry3d estimated = T_map_from.inverse() * T_map_to;
  const Eigen::Matrix3d r_error = estimated.rotation() * T_from_to.rotation().transpose();
  const Eigen::AngleAxisd angle_axis(r_error);
  Eigen::Matrix<double, 6, 1> error;
  error.head<3>() = angle_axis.angle() * angle_axis.axis();
  error.tail<3>() = estimated.translation() - r_error * T_from_to.translation();
  return error;
}

size_t PoseGraph::add_node(const Eigen::Isometry3d& T_map_node) {
  poses_.push_back(T_map_node);
  return poses_.size() - 1;
}

void PoseGraph::add_edge(const PoseGraphEdge& edge) {
  if (edge.from >= poses_.size() || edge.to >= poses_.size() || edge.from == edge.to) {
    throw std::invalid_argument("pose graph: an edge between nodes " + std::to_string(edge.from) +
                                " and " + std::to_string(edge.to) + " of " +
                                std::to_string(poses_.size()));
  }
  if (!edge.information.allFinite() ||
      !edge.information.isApprox(edge.information.transpose(), 1e-9))
    throw std::invalid_argument("pose graph: an edge's information is not symmetric");
  square_root(edge.information);  // throws where it is not positive definite
  edges_.push_back(edge);
}

void PoseGraph::add_gravity(const GravityObservation& observation, double bias_prior_mps2) {
  if (observation.node >= poses_.size())
    throw std::invalid_argument("pose graph: a gravity observation of node " +
                                std::to_string(observation.node) + " of " +
                                std::to_string(poses_.size()));
  if (!(observation.sigma_rad > 0.0) || !std::isfinite(observation.sigma_rad) ||
      !(bias_prior_mps2 > 0.0) || !observation.up().allFinite() || observation.up().norm() == 0.0)
    throw std::invalid_argument("pose graph: a gravity observation without a direction or sigma");
  gravity_.push_back(observation);
  bias_prior_mps2_ = bias_prior_mps2;
}

void PoseGraph::add_gyro(const GyroObservation& observation, double bias_prior_radps) {
  if (observation.from >= poses_.size() || observation.to >= poses_.size() ||
      observation.from == observation.to)
    throw std::invalid_argument(
        "pose graph: a gyroscope edge between nodes " + std::to_string(observation.from) + " and " +
        std::to_string(observation.to) + " of " + std::to_string(poses_.size()));
  if (!(observation.sigma_rad.minCoeff() > 0.0) || !observation.sigma_rad.allFinite() ||
      !(bias_prior_radps > 0.0) || !observation.delta.allFinite() ||
      !observation.bias_jacobian.allFinite())
    throw std::invalid_argument("pose graph: a gyroscope edge without a rotation or sigma");
  gyro_.push_back(observation);
  gyro_bias_prior_radps_ = bias_prior_radps;
}

double PoseGraph::whitened_error(const PoseGraphEdge& edge) const {
  const Eigen::Matrix<double, 6, 1> e =
      edge_error(poses_[edge.from], poses_[edge.to], edge.T_from_to);
  return std::sqrt(std::max(0.0, e.dot(edge.information * e)));
}

PoseGraphSummary PoseGraph::optimize(const PoseGraphSettings& settings) {
  PoseGraphSummary summary;
  if (poses_.size() < 2 || edges_.empty()) {
    summary.converged = true;
    return summary;
  }
  std::vector<Eigen::Vector3d> translations(poses_.size());
  std::vector<Eigen::Quaterniond> rotations(poses_.size());
  for (size_t i = 0; i < poses_.size(); ++i) {
    translations[i] = poses_[i].translation();
    rotations[i] = Eigen::Quaterniond(poses_[i].rotation()).normalized();
  }
  ceres::Problem problem;
  for (size_t i = 0; i < poses_.size(); ++i) {
    problem.AddParameterBlock(translations[i].data(), 3);
    problem.AddParameterBlock(rotations[i].coeffs().data(), 4, new ceres::EigenQuaternionManifold);
  }
  problem.SetParameterBlockConstant(translations[0].data());
  problem.SetParameterBlockConstant(rotations[0].coeffs().data());

  // Every loop within the first scale: the first solve is a plain least-squares one.
  double scale = settings.final_loss_scale;
  for (const PoseGraphEdge& edge : edges_) {
    if (edge.loop) scale = std::max(scale, whitened_error(edge));
  }
  std::vector<ceres::LossFunctionWrapper*> loop_losses;
  for (const PoseGraphEdge& edge : edges_) {
    ceres::LossFunction* loss = nullptr;
    if (edge.loop) {
      loop_losses.push_back(
          new ceres::LossFunctionWrapper(new ceres::CauchyLoss(scale), ceres::TAKE_OWNERSHIP));
      loss = loop_losses.back();
    }
    auto* cost = new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 3, 4, 3, 4>(
        new RelativePoseCost(edge.T_from_to, square_root(edge.information)));
    problem.AddResidualBlock(cost, loss, translations[edge.from].data(),
                             rotations[edge.from].coeffs().data(), translations[edge.to].data(),
                             rotations[edge.to].coeffs().data());
  }

  const BiasBasis basis = bias_basis(gravity_);
  Eigen::Vector2d bias_coordinates = basis.transpose() * accel_bias_;
  for (const GravityObservation& observation : gravity_) {
    // Huber: a window spoilt by a jolt the odometry's velocities missed pulls, but only so far.
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<GravityCost, 2, 4, 2, 2>(
                                 new GravityCost(observation, basis)),
                             new ceres::HuberLoss(3.0), rotations[observation.node].coeffs().data(),
                             map_tilt_rad_.data(), bias_coordinates.data());
  }
  if (!gravity_.empty()) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BiasPriorCost<2>, 2, 2>(
                                 new BiasPriorCost<2>(bias_prior_mps2_)),
                             nullptr, bias_coordinates.data());
  }
  for (const GyroObservation& observation : gyro_) {
    // Huber: an edge over a jolt or a clock's jump pulls, but only so far.
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<GyroCost, 3, 4, 4, 3>(new GyroCost(observation)),
        new ceres::HuberLoss(3.0), rotations[observation.from].coeffs().data(),
        rotations[observation.to].coeffs().data(), gyro_bias_.data());
  }
  if (!gyro_.empty()) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<BiasPriorCost<3>, 3, 3>(
                                 new BiasPriorCost<3>(gyro_bias_prior_radps_)),
                             nullptr, gyro_bias_.data());
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = settings.max_iterations_per_solve;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  bool first = true;
  summary.converged = true;
  while (true) {
    ceres::Solver::Summary solve;
    ceres::Solve(options, &problem, &solve);
    ++summary.solves;
    summary.iterations += static_cast<int>(solve.iterations.size());
    if (first) summary.initial_cost = solve.initial_cost;
    first = false;
    summary.final_cost = solve.final_cost;
    if (!solve.IsSolutionUsable()) {
      summary.converged = false;
      return summary;  // the poses stay as they were
    }
    summary.converged = solve.termination_type == ceres::CONVERGENCE;
    if (scale <= settings.final_loss_scale) break;
    scale = std::max(settings.final_loss_scale, scale / std::max(settings.loss_scale_step, 1.5));
    for (ceres::LossFunctionWrapper* loss : loop_losses)
      loss->Reset(new ceres::CauchyLoss(scale), ceres::TAKE_OWNERSHIP);
  }
  summary.gyro_edges = gyro_.size();
  summary.gyro_bias_radps = gyro_bias_;
  // With gravity, the poses go into the vertical frame: the map frame tilted back by what the
  // observations of every node say (the first node alone, held fixed, would decide it else).
  Eigen::Isometry3d level = Eigen::Isometry3d::Identity();
  if (!gravity_.empty()) {
    accel_bias_ = basis * bias_coordinates;
    summary.gravity.accel_bias_mps2 = accel_bias_;
    level = level_by_gravity(gravity_, basis, rotations, translations[0], bias_coordinates,
                             bias_prior_mps2_, map_tilt_rad_, summary.gravity);
  }
  for (size_t i = 0; i < poses_.size(); ++i) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rotations[i].normalized().toRotationMatrix();
    pose.translation() = translations[i];
    poses_[i] = level * pose;
  }
  for (const PoseGraphEdge& edge : edges_) {
    if (!edge.loop) continue;
    const double chi = whitened_error(edge);
    summary.loop_chi.push_back(chi);
    summary.loop_weights.push_back(1.0 / (1.0 + (chi * chi) / (scale * scale)));
  }
  return summary;
}

}  // namespace featsense::slam::loops
