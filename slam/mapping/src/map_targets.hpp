#pragma once
// The part of a saved map's surface that scans are registered to: the voxels of voxelized
// GICP made from the surface cells (map_surface.hpp) within a radius of the sensor. A target
// serves while the sensor stays near its centre; once the sensor has moved a quarter of the
// radius, the next is made on a thread of its own from the cells around the sensor's place
// then, so that tracking never waits for the file, except where it jumps (the first target,
// a sensor found somewhere else).

#include <Eigen/Core>

#include <condition_variable>
#include <cstddef>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <unordered_set>
#include <utility>
#include <vector>

#include "featsense/slam/refine/vgicp.hpp"
#include "keyframe_points.hpp"
#include "map_path.hpp"
#include "map_surface.hpp"

namespace featsense::mapping {

struct MapTarget {
  MapTarget(const Eigen::Vector3d& centre_in, slam::refine::VgicpTarget vgicp_in)
      : centre(centre_in), vgicp(std::move(vgicp_in)) {}
  Eigen::Vector3d centre;
  slam::refine::VgicpTarget vgicp;
  /// grid_key() of the blocks (block_m across) where the map observed anything.
  std::unordered_set<uint64_t> observed;
  double block_m = 0.5;
  /// Horizontal positions of the upright surface cells (walls, posts: normal within
  /// build_map_target's upright_max_normal_z of the horizontal), where it was asked for them.
  std::vector<Eigen::Vector2f> upright;
  /// ... and of the columns of observed blocks (once each), where upright cells were asked for.
  std::vector<Eigen::Vector2f> observed_columns;
  /// Where the map's path passed nearest to each place of the target, where the map has a
  /// path: from how far its surfaces were seen.
  std::optional<SeenFrom> seen_from;
};

/// How a scan placed at a pose fits the map: of its points where the map observed anything,
/// the share within `inlier_distance_m` of the surface (the rest contradict the map: free
/// space there, or a surface elsewhere); and the share of its points the map observed at all
/// (the rest say nothing: the map never looked there).
struct MapFit {
  size_t points = 0;
  size_t observed = 0;
  size_t inliers = 0;
  double inlier_fraction = 0.0;  ///< inliers / observed
  double coverage = 0.0;         ///< observed / points
  double fitness_m = 0.0;        ///< RMS distance of the inliers to the surface
  /// How firmly the inliers hold the pose: the standard deviation of its position along the
  /// direction they constrain least, and of its heading and tilt about the axis they
  /// constrain least, from their distances to the surface's planes (each an independent
  /// measurement of fitness_m's spread). Infinite where they leave a direction free (a
  /// street's facades seen alone fix nothing along the street).
  double position_sigma_m = std::numeric_limits<double>::infinity();
  double rotation_sigma_deg = std::numeric_limits<double>::infinity();
  /// How far the map's own surfaces may have moved the pose: each inlier's surface known to
  /// `surface_angle_sigma_rad` times how obliquely and from how far the map saw it
  /// (surface_sigma), and the error of a surface shared by all its points. Where the sensor
  /// stands on ground the map saw only from 30 m, this is what its height is worth, however
  /// many points hold it. 0 where the target has no path.
  double surface_position_m = 0.0;
  double surface_rotation_deg = 0.0;
  /// The same counts for the scan's points on upright surfaces (walls, posts, trunks: the
  /// normal of the scan's surface at the point within kUprightMaxNormalZ of level). The
  /// ground is flat almost everywhere and fits at a place metres off as well as at the right
  /// one; what tells a place from another that looks alike is what stands on the ground.
  size_t upright_observed = 0;
  size_t upright_inliers = 0;
  double upright_inlier_fraction = 0.0;  ///< upright_inliers / upright_observed
};
/// A surface is upright where its normal's vertical part is at most this (60 deg from level).
constexpr double kUprightMaxNormalZ = 0.5;
MapFit measure_map_fit(const MapTarget& target, const slam::refine::GaussianCloud& cloud,
                       const Eigen::Isometry3d& T, double inlier_distance_m,
                       double surface_angle_sigma_rad = 0.0);

/// The target of the surface within `radius_m` (horizontally) of `centre`, with voxels of
/// `voxel_sizes_m` (multiples of the surface's cells) and the fit's voxels of `fitness_voxel_m`,
/// the observed blocks of `block_m`, and its upright cells where `upright_max_normal_z` >= 0.
/// Reads what the surface has not cached.
/// Where `beyond` is given, its points in blocks the surface did not observe join the target
/// (each with its neighbours' covariance) and their blocks count as observed: a target for
/// checking a place found from scratch, not for tracking (they are less accurate than the
/// surface: a keyframe's heading error times the range they were seen at).
/// Where `path` is given, the target knows from where its surfaces were seen (seen_from).
std::shared_ptr<const MapTarget> build_map_target(MapSurface& surface,
                                                  const Eigen::Vector3d& centre, double radius_m,
                                                  const std::vector<double>& voxel_sizes_m,
                                                  double fitness_voxel_m, double block_m,
                                                  double upright_max_normal_z = -1.0,
                                                  const KeyframePoints* beyond = nullptr,
                                                  const MapPath* path = nullptr);

struct MapTargetCounts {
  size_t built = 0;
  size_t waited = 0;  ///< targets the tracking had to wait for
  double build_ms = 0.0;
  double wait_ms = 0.0;
};

class MapTargets {
 public:
  /// Targets of `radius_m` around the sensor with the voxels of `vgicp` (its voxel sizes must
  /// be multiples of the surface's cells, the finest the cell itself).
  MapTargets(MapSurface& surface, double radius_m, const slam::refine::VgicpSettings& vgicp,
             double block_m, const MapPath* path = nullptr);
  ~MapTargets();
  MapTargets(const MapTargets&) = delete;
  MapTargets& operator=(const MapTargets&) = delete;

  /// A target for a sensor at `position`. Asks for the next in the background where the
  /// sensor has moved a quarter of the radius from the current one's centre, and takes it
  /// where the sensor has moved three eighths of the radius, waiting for it if it is not
  /// made yet (one made now where it is of no use there). Which target a scan is registered
  /// to depends on where the sensor is, never on how fast the background was: a run over
  /// the same scans gives the same poses to the bit.
  std::shared_ptr<const MapTarget> around(const Eigen::Vector3d& position);

  MapTargetCounts counts() const;

 private:
  std::shared_ptr<const MapTarget> build(const Eigen::Vector3d& centre);
  void run();

  MapSurface& surface_;
  double radius_m_;
  slam::refine::VgicpSettings vgicp_;
  double block_m_;
  const MapPath* path_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::shared_ptr<const MapTarget> current_;
  /// The background's, once made, until it is taken.
  std::shared_ptr<const MapTarget> next_;
  std::optional<Eigen::Vector3d> requested_;
  bool building_ = false;
  bool stop_ = false;
  MapTargetCounts counts_;
  std::thread thread_;
};

}  // namespace featsense::mapping
