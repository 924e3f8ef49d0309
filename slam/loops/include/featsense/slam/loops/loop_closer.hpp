#pragma once
/// Loop closure over keyframes (KeyframeSelector picks them): each keeps its pose, its points
/// (thinned, compact) and its Scan Context.
/// Each new keyframe looks for earlier ones it may revisit, never the recent past:
///  - by its descriptor (ring key, then the full match, which also gives the relative yaw:
///    revisits in the opposite direction are found too), and
///  - by position, within a radius that grows with the distance travelled since the last
///    closure (the odometry's drift).
/// Each candidate is verified by voxelized GICP against the candidate keyframe and its
/// neighbours, from the descriptor's yaw or the current poses, and must fit well (fitness,
/// inliers). A verified loop must also agree with the odometry: the place it puts the new
/// keyframe lies within the drift radius of where the odometry puts it (a block exactly like
/// another one elsewhere fails here), and two verified candidates that put it at different
/// places are rejected both (ambiguous). What is rejected is counted, by reason.
/// Accepted loops become edges of a pose graph over the keyframes (odometry edges between
/// consecutive keyframes, with information from the registration's Hessian), optimised at
/// once. Not thread-safe: one caller, keyframes in order.

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/loops/compact_cloud.hpp"
#include "featsense/slam/loops/gravity_reference.hpp"
#include "featsense/slam/loops/pose_graph.hpp"
#include "featsense/slam/loops/scan_context.hpp"
#include "featsense/slam/loops/trajectory_correction.hpp"
#include "featsense/slam/refine/gaussian_cloud.hpp"
#include "featsense/slam/refine/vgicp.hpp"

namespace featsense::slam::loops {

/// The registration that verifies a loop candidate: coarse voxels first (a descriptor's guess
/// is metres off), a good fit at the end.
inline refine::VgicpSettings verification_vgicp() {
  refine::VgicpSettings settings;
  settings.voxel_sizes_m = {4.0, 2.0, 1.0, 0.5};
  settings.max_iterations = 20;
  settings.step_tolerance_m = 5e-4;
  settings.inlier_distance_m = 0.2;
  settings.fitness_voxel_m = 0.5;
  return settings;
}

/// Where a setting has a config key (loop.*), its default is the configuration's
/// (config/include/featsense/config/config.hpp): one home per default.
struct LoopSettings {
  /// KeyframeSelector's spacing: metres travelled or degrees turned.
  double keyframe_distance_m = config::LoopConfig{}.keyframe_distance_m;
  double keyframe_angle_deg = config::LoopConfig{}.keyframe_angle_deg;
  /// Candidates are at least this old and this far back along the path.
  double min_separation_s = config::LoopConfig{}.min_separation_s;
  double min_separation_m = config::LoopConfig{}.min_separation_m;
  ScanContextSettings scan_context;
  /// Keyframes compared in full after the ring keys, and the largest descriptor distance that
  /// makes a candidate.
  size_t descriptor_candidates = 6;
  /// Of those within max_descriptor_distance, the best this many are verified.
  size_t descriptor_verifications = 1;
  double max_descriptor_distance = config::LoopConfig{}.max_descriptor_distance;
  /// The odometry's drift: the position search radius and the consistency check's tolerance
  /// are base + per_m x the distance travelled since the last closure.
  double drift_base_m = 2.0;
  double drift_per_m = config::LoopConfig{}.drift;
  double drift_base_deg = 5.0;
  double drift_deg_per_m = 0.02;
  size_t position_candidates = 1;
  /// After an accepted loop the search rests for this many metres: the next keyframes would
  /// find the same revisit again, at the cost of a registration each.
  double search_rest_m = 5.0;
  /// The keyframes' points: one per voxel of this edge, covariances from this many nearest.
  double cloud_voxel_m = 0.4;
  int neighbours = 10;
  /// The verification: coarse voxels first (a descriptor's guess is metres off), a good fit
  /// at the end.
  refine::VgicpSettings vgicp = verification_vgicp();
  double max_fitness_m = config::LoopConfig{}.max_fitness_m;
  double min_inlier_fraction = config::LoopConfig{}.min_inlier_fraction;
  /// A keyframe is registered against the candidate and this many keyframes on either side.
  size_t target_neighbours = 2;
  /// Two verified candidates that place the keyframe this far apart are ambiguous.
  double ambiguity_m = 1.0;
  /// The odometry edges' drift (standard deviation per metre travelled between keyframes)
  /// and the floor of every edge's standard deviation.
  double odometry_sigma_per_m = 0.005;
  double odometry_sigma_rad_per_m = 1e-4;
  double min_sigma_m = 0.01;
  double min_sigma_rad = 1e-3;
  PoseGraphSettings graph;
  /// The IMU's gravity as the graph's vertical reference (gravity_reference.hpp).
  GravitySettings gravity;
  /// The IMU's gyroscope between keyframes (gyro_reference.hpp).
  GyroSettings gyro;
};

/// loop.* of `config`.
LoopSettings from_config(const config::Config& config);

/// The information of an edge measured by a registration: the shape of its Hessian (over
/// `points` terms) at the scale of its fitness, plus the odometry's drift over `travelled_m`
/// and the settings' floor. Without a Hessian (0 points): the drift and the floor alone.
Matrix6d edge_information(const LoopSettings& settings, const Matrix6d& hessian, size_t points,
                          double fitness_m, double travelled_m);

/// Picks the keyframes among the scans, in order: the first, then one every `distance_m`
/// travelled or `angle_deg` turned since the last keyframe.
class KeyframeSelector {
 public:
  KeyframeSelector(double distance_m, double angle_deg);
  /// The next scan's pose; true when it makes a keyframe.
  bool next(const Eigen::Isometry3d& T_map_sensor);
  /// The distance along the path at the last scan given, metres.
  double travelled_m() const { return travelled_m_; }

 private:
  double distance_m_;
  double angle_deg_;
  bool started_ = false;
  double travelled_m_ = 0.0;
  Eigen::Isometry3d last_pose_ = Eigen::Isometry3d::Identity();
  double keyframe_travelled_m_ = 0.0;
  Eigen::Isometry3d keyframe_pose_ = Eigen::Isometry3d::Identity();
};

/// Why a candidate did not become a loop.
enum class LoopRejection { not_converged, fitness, inliers, inconsistent, ambiguous };
const char* to_string(LoopRejection reason);

/// Why a registration of a revisit fails the fit (not converged, fitness, inliers): none
/// where it passes. The checks of loops, relocalization and links between sessions.
std::optional<LoopRejection> fit_rejection(const refine::VgicpResult& result,
                                           const LoopSettings& settings);

/// An accepted loop: keyframe `query` revisits keyframe `candidate`.
struct LoopRecord {
  size_t query = 0;
  size_t candidate = 0;
  int64_t query_stamp_ns = 0;
  int64_t candidate_stamp_ns = 0;
  std::string found_by;  ///< "descriptor" or "position"
  double descriptor_distance = 1.0;
  double fitness_m = 0.0;
  double inlier_fraction = 0.0;
  /// How far the optimisation moved the query keyframe when this loop was added.
  double correction_m = 0.0;
  double correction_deg = 0.0;
  double weight = 1.0;  ///< the pose graph's final weight of the loop (near 0: overruled)
};

struct LoopCounts {
  size_t keyframes = 0;
  size_t candidates = 0;
  size_t verified = 0;                     ///< registrations that passed the fit
  std::map<std::string, size_t> rejected;  ///< by to_string(LoopRejection)
  size_t optimisations = 0;
  std::vector<double> keyframe_ms;  ///< per keyframe: descriptor, candidates, verification
  std::vector<double> optimise_ms;
  size_t cloud_bytes = 0;  ///< the keyframes' compact clouds
};

/// A keyframe as a map keeps it for later sessions: where the graph puts it now, its place
/// descriptor and its points.
struct KeyframeRecord {
  int64_t stamp_ns = 0;
  double travelled_m = 0.0;  ///< along its run's path
  Eigen::Isometry3d T_map_sensor = Eigen::Isometry3d::Identity();
  ScanContext descriptor;
  CompactCloud cloud;
};

class LoopCloser {
 public:
  explicit LoopCloser(const LoopSettings& settings);

  /// Adds a keyframe: the scan's pose as the front end gave it, its stamp, how far along the
  /// path, and its points in the sensor frame (deskewed, thinned to cloud_voxel_m). Searches,
  /// verifies and, with a new loop, optimises the graph. True when a loop was accepted.
  bool add_keyframe(int64_t stamp_ns, double travelled_m, const Eigen::Isometry3d& T_map_sensor,
                    const std::vector<Eigen::Vector3f>& points);

  /// A loop edge from outside (a known constraint, or a test's deliberately wrong one): the
  /// pose of keyframe `query` in keyframe `candidate`'s frame. Optimises.
  void add_loop_edge(size_t candidate, size_t query, const Eigen::Isometry3d& T_candidate_query,
                     const Matrix6d& information);

  /// The end of a run: the gravity the IMU's `samples` (time order) saw around each keyframe,
  /// with the rotations and positions of the front end's `path` (every scan's stamp and pose,
  /// stamps increasing), goes into the graph (none without samples or with loop.gravity off),
  /// and so does the gyroscope's turn between keyframes, weighed against the LiDAR's (none
  /// with loop.gyro off); the graph is optimised once more where it holds any of them. Its summary,
  /// empty where nothing was optimised.
  PoseGraphSummary finish(const std::vector<int64_t>& path_stamps_ns,
                          const std::vector<Eigen::Isometry3d>& path,
                          const std::vector<ImuSample>& samples);

  /// Optimises the graph with every loop and gravity observation (at the end of a run).
  PoseGraphSummary optimise();

  /// The correction of the poses between keyframes, from the graph's current poses.
  TrajectoryCorrection correction() const;

  size_t keyframes() const { return keyframes_.size(); }
  /// Every keyframe in order, at the graph's current pose.
  std::vector<KeyframeRecord> keyframe_records() const;
  /// keyframe_records() with the clouds moved out of the closer, for the end of a run: the
  /// clouds are most of a long run's keyframes (80 MB a kilometre of city), and a copy of them
  /// would be held as long as the records are. Keyframes added later, and the loops they
  /// search, see these keyframes without points.
  std::vector<KeyframeRecord> release_keyframe_records();
  const std::vector<LoopRecord>& loops() const { return loops_; }
  const LoopCounts& counts() const { return counts_; }
  const PoseGraph& graph() const { return graph_; }

 private:
  struct Keyframe {
    int64_t stamp_ns = 0;
    double travelled_m = 0.0;
    Eigen::Isometry3d T_front_end;  ///< the pose the front end gave it
    ScanContext descriptor;
    CompactCloud cloud;
  };
  struct Candidate {
    size_t keyframe = 0;
    Eigen::Isometry3d guess;  ///< T_candidate_query
    std::string found_by;
    double descriptor_distance = 1.0;
  };
  std::vector<Candidate> find_candidates(size_t query) const;
  double drift_radius_m(size_t query) const;
  double drift_radius_deg(size_t query) const;
  refine::GaussianCloud target_around(size_t keyframe) const;
  void add_odometry_edge(size_t keyframe, const refine::GaussianCloud& cloud);
  PoseGraphSummary optimise_timed();
  /// The odometry edges' turns under `turns` (consecutive keyframes), in order; a turn
  /// without one is dropped from `turns`.
  std::vector<LidarTurn> lidar_turns(std::vector<GyroObservation>* turns) const;

  LoopSettings settings_;
  std::vector<Keyframe> keyframes_;
  PoseGraph graph_;
  refine::GaussianCloud previous_cloud_;  ///< the last keyframe's, for its odometry edge
  double last_closure_m_ = 0.0;           ///< travelled_m of the last accepted loop
  std::vector<LoopRecord> loops_;
  LoopCounts counts_;
};

}  // namespace featsense::slam::loops
