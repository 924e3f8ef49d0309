#pragma once
/// A pose graph over keyframes, optimised with Ceres: nodes are keyframe poses (map <- sensor),
/// edges relative poses measured between two of them with their information. Odometry edges
/// are trusted as measured; loop edges go through a Cauchy loss whose scale shrinks over a few
/// solves (graduated non-convexity): at first every loop pulls, and a loop that disagrees with
/// the others and with the odometry ends with a weight near 0 instead of bending the map.
/// Where an IMU saw gravity (gravity_reference.hpp), each observation pulls its node's up
/// direction to the vertical; two more variables take what the map frame (the first node,
/// held fixed) is tilted from the vertical, and the accelerometer's bias. The solved poses are
/// then turned towards the vertical frame (Z up, the first node's position and heading kept)
/// by as much of that tilt as gravity is sure of: the map is level with gravity, whatever the
/// first scan's tilt, once the path has turned enough to tell the bias from a tilt.
/// Where the IMU's gyroscope turned between two nodes (gyro_reference.hpp), an edge ties their
/// relative rotation to its turn, less its bias (one more variable).

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstddef>
#include <vector>

#include "featsense/slam/loops/gravity_reference.hpp"
#include "featsense/slam/loops/gyro_reference.hpp"

namespace featsense::slam::loops {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// A relative pose T_from_to (from <- to) measured between two nodes. Its error is the
/// perturbation that takes the measured pose to the estimated one, applied on the left:
/// [Log(R_est R_meas^T); t_est - R_est R_meas^T t_meas], the tangent that voxelized GICP's
/// Hessian is given in (rotation first, radians, then metres).
struct PoseGraphEdge {
  size_t from = 0;
  size_t to = 0;
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Identity();
  bool loop = false;  ///< robust (a loop) or trusted (the odometry's chain)
};

struct PoseGraphSettings {
  /// The Cauchy scale of loop edges ends at this many standard deviations: a loop whose
  /// whitened error is beyond a few of them is down-weighted.
  double final_loss_scale = 3.0;
  /// Each solve divides the scale by this, from where every loop is within it.
  double loss_scale_step = 4.0;
  int max_iterations_per_solve = 50;
};

/// What the gravity observations told, after a solve.
struct GravityEstimate {
  size_t observations = 0;
  /// How far the front end's map frame (the first node's) is tilted from the vertical, about
  /// its x and y axes, degrees, and that tilt's standard deviation from gravity alone (the
  /// accelerometer's bias is told from a tilt only where the path turns).
  Eigen::Vector2d map_tilt_deg = Eigen::Vector2d::Zero();
  double tilt_sigma_deg = 0.0;
  /// The rotation the poses were levelled by: the tilt shrunk by its significance (none
  /// within one sigma).
  double levelled_deg = 0.0;
  /// The accelerometer's bias across the up direction (along it, it is not observable).
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();
  /// The root mean square of the observations' whitened errors (about 1 when the model's
  /// noise is right).
  double rms_whitened = 0.0;
};

struct PoseGraphSummary {
  int solves = 0;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  bool converged = false;
  /// Per loop edge in the order added: its whitened error at the end and the weight the loss
  /// gave it (1: obeyed, near 0: rejected by the graph).
  std::vector<double> loop_chi;
  std::vector<double> loop_weights;
  GravityEstimate gravity;
  /// The gyroscope's edges and the bias found for it, rad/s (zero without edges).
  size_t gyro_edges = 0;
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();
  /// How the gyroscope's turns and the LiDAR's agreed (filled by LoopCloser::finish).
  TurnAgreement turn_agreement;
  GravityAgreement gravity_agreement;
};

class PoseGraph {
 public:
  /// Adds a node at its first estimate; the first node added is held fixed (the map frame).
  size_t add_node(const Eigen::Isometry3d& T_map_node);
  /// Throws std::invalid_argument for a node index out of range, a self edge or an
  /// information matrix that is not symmetric positive definite.
  void add_edge(const PoseGraphEdge& edge);
  /// Throws std::invalid_argument for a node out of range or a sigma that is not positive.
  void add_gravity(const GravityObservation& observation, double bias_prior_mps2);
  /// Throws std::invalid_argument for a node out of range, a self edge or a sigma that is not
  /// positive.
  void add_gyro(const GyroObservation& observation, double bias_prior_radps);
  PoseGraphSummary optimize(const PoseGraphSettings& settings = {});

  size_t size() const { return poses_.size(); }
  const Eigen::Isometry3d& pose(size_t node) const { return poses_[node]; }
  const std::vector<Eigen::Isometry3d>& poses() const { return poses_; }
  const std::vector<PoseGraphEdge>& edges() const { return edges_; }

  /// The whitened error of an edge at the current poses (sqrt of e^T I e).
  double whitened_error(const PoseGraphEdge& edge) const;

 private:
  std::vector<Eigen::Isometry3d> poses_;
  std::vector<PoseGraphEdge> edges_;
  std::vector<GravityObservation> gravity_;
  double bias_prior_mps2_ = 0.2;
  /// The map frame's tilt (angle-axis about x and y) and the bias, kept between solves.
  Eigen::Vector2d map_tilt_rad_ = Eigen::Vector2d::Zero();
  Eigen::Vector3d accel_bias_ = Eigen::Vector3d::Zero();
  std::vector<GyroObservation> gyro_;
  double gyro_bias_prior_radps_ = 0.02;
  Eigen::Vector3d gyro_bias_ = Eigen::Vector3d::Zero();
};

/// The error of an edge measured as T_from_to between poses at `T_map_from` and `T_map_to`, in
/// the tangent of PoseGraphEdge.
Eigen::Matrix<double, 6, 1> edge_error(const Eigen::Isometry3d& T_map_from,
                                       const Eigen::Isometry3d& T_map_to,
                                       const Eigen::Isometry3d& T_from_to);

}  // namespace featsense::slam::loops
