#pragma once
/// Localization in a saved map: each scan's pose in the map's frame, the map left as it was.
///
/// The states, scan by scan:
///  - lost: nowhere yet (the start, or after the map was lost). The odometry runs in a frame
///    of its own and its keyframes are matched against the map's stored keyframes
///    (`slam::loops::Relocalizer`: place descriptors, verification by registration, several
///    keyframes that agree). A match is then checked once more against the map's surface;
///    until it passes, no pose is given.
///  - localized: the scan registered to the map's surface around the predicted pose
///    (voxelized GICP, the surface of the TSDF as the target: map_targets) and it fits: enough
///    of its points lie on the map's surface, closely enough, they hold the pose firmly, and
///    the surfaces they lie on were seen from near enough to be sure of (map_path). The
///    prediction is constant velocity from the last two poses, turned as the gyroscope
///    measured where the scans carry IMU samples (and deskews the scan), or the odometry's
///    motion while that still runs.
///  - odometry: the scan did not fit well enough (changed surroundings, a place the map never
///    saw, a view blocked): the odometry, started at the last pose, carries the pose on and
///    the registration is tried again from it each scan. Too long on odometry, or several
///    scans in a row that contradict the map (almost none of their points on it), and the
///    sensor is lost.
/// Why the TSDF's surface as the target, not the keyframes' clouds: it is the map the robot
/// navigates on (the navigation mesh is made from it), every surface averaged over every scan
/// that saw it rather than a few thinned scans, complete between keyframes, and read from the
/// store region by region (a bounded cache, never the whole map).
/// Not thread-safe: one caller, scans in order.

#include <Eigen/Geometry>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/refine/vgicp.hpp"
#include "featsense/slam/scan.hpp"

namespace featsense::mapping {

enum class LocalizeStatus { kLost, kLocalized, kOdometry };
/// "lost", "localized", "odometry": the words of the status file and the report.
const char* to_string(LocalizeStatus status);

/// localize.* of the configuration, and what has no key.
struct LocalizerSettings {
  double radius_m = config::LocalizeConfig{}.radius_m;
  size_t cache_bytes = static_cast<size_t>(config::LocalizeConfig{}.cache_mb * 1024 * 1024);
  double voxel_m = config::LocalizeConfig{}.voxel_m;
  size_t max_points = static_cast<size_t>(config::LocalizeConfig{}.max_points);
  double min_inlier_fraction = config::LocalizeConfig{}.min_inlier_fraction;
  double max_fitness_m = config::LocalizeConfig{}.max_fitness_m;
  double contradiction_fraction = config::LocalizeConfig{}.contradiction_fraction;
  size_t contradictions = static_cast<size_t>(config::LocalizeConfig{}.contradictions);
  double odometry_timeout_s = config::LocalizeConfig{}.odometry_timeout_s;
  /// The registration to the map: from a prediction a few centimetres off, so a few coarse
  /// iterations and fine voxels (the finest is the cell the map's surface is summed in).
  slam::refine::VgicpSettings vgicp = tracking_vgicp();
  /// A fit needs this many of the scan's points where the map observed anything, and this
  /// share of them: a scan the map saw little of (a street it only glimpsed from a crossing)
  /// can fit the little it saw well at a pose a few decimetres off.
  size_t min_observed_points = 50;
  double min_coverage = 0.25;
  /// ... and its points on the surface must hold the pose this firmly (the standard deviation
  /// along the direction, and about the axis, they constrain least: MapFit). A street's
  /// facades alone leave the pose free along the street; a thinned OS1-128 scan in a street
  /// the map knows holds it to 3-7 mm, one that sees a street the map only glimpsed to 3-6 cm.
  /// A fit held this firmly stands also where the registration's last steps still traded
  /// voxels (not converged within its iterations): it cannot slide.
  double max_position_sigma_m = 0.015;
  double max_rotation_sigma_deg = 0.1;
  /// ... and the map's own surfaces must not be able to move it more than this
  /// (MapFit::surface_position_m): a surface is known to `surface_angle_sigma_deg` times the
  /// range, across the line of sight, that the map saw it at (map_path.hpp). The angle: in
  /// the town the map's height erred by 0.6-1.1 mm a metre of the sensor's distance from the
  /// map's path, a fraction of an OS1-128 beam's divergence (0.18 deg). The bound: there (four
  /// runs, 2,550 localized scans) the height erred by about 0.4 of it, RMS, so at 40 mm its
  /// three sigma is within 5 cm; the scans it bounded by 30-40 mm were at most 37 mm off all
  /// told, one it bounded by 42 mm 65 mm off. The limit holds for this bound and the
  /// position's own sigma together (independent: their root sum of squares): a scan bounded by
  /// 39.9 mm, its position held to 13.3 mm, was 65 mm off (the drive from its scan 640).
  double surface_angle_sigma_deg = 0.05;
  double max_surface_position_m = 0.04;
  /// Covariances of a scan's points from this many nearest.
  int neighbours = 10;
  /// Voxels of the map's surface observed at least this much (as its mesh's).
  double min_weight = 0.5;
  /// The tracking's first registration of a scan that follows a localized one starts at this
  /// level of the voxels (0: the coarsest, vgicp.voxel_sizes_m).
  size_t steady_first_level = 1;
  /// ... and weighs each point under Geman-McClure's kernel of this scale on its Mahalanobis
  /// distance (VgicpSettings::robust_scale; 0: least squares). What the map does not hold (a
  /// car parked since, a door closed) lies decimetres off its surfaces: distances of 4 and
  /// more under two planes' covariances (0.045 m across), weighed a few thousandths and less;
  /// the scan's points on the map's surfaces lie within a centimetre or two (distances below
  /// 0.5, weights above 0.6). The town's drive with its parked cars moved: the worst
  /// localized pose 109 -> 36 mm. Not from a prediction of the odometry's or a place just
  /// found: there a kernel lets a wrong place fit the part of the scan that matches it.
  double tracking_robust_scale = 1.0;
  /// Fits in a row after which the odometry stops and constant velocity predicts.
  size_t settle_scans = 5;
  /// The search: each place a keyframe's descriptor proposes is checked by registering the
  /// keyframe to the map's surface within this radius of it, from the coarsest of these
  /// voxels (the guess is the map keyframe's place: metres off where the sensor drives in
  /// another lane or walks the sidewalk; the finest need not be the tracking's to tell the
  /// place), and judged as a tracked scan is. The descriptors of a town's crossings and
  /// streets are much alike: more candidates are checked than `map --continue` checks.
  double search_radius_m = 30.0;
  std::vector<double> search_voxel_sizes_m = {2.0, 1.0, 0.5};
  /// The search's keyframes are made as the mapping's are (loop.keyframe_distance and
  /// keyframe_angle_deg of motion), and where the sensor has not moved that much, one this
  /// often: a robot standing still (at its dock, at power-on) is found without moving, from
  /// two of its scans that agree on its place.
  double search_keyframe_interval_s = 1.0;
  /// Targets of places checked kept for the next keyframes' candidates (the same places).
  size_t search_targets_kept = 8;
  size_t search_ring_candidates = 50;
  size_t search_verifications = 8;
  /// Each proposed place is registered from the few places within this distance of it (each
  /// way along x and along y) where the keyframe's upright surfaces, seen from above, best
  /// cover the map's: a descriptor finds the street, often at a keyframe metres along it,
  /// farther than a registration slides. 0: from the proposed place alone.
  double search_reach_m = 24.0;
  /// A place found from scratch needs this much more of the scan on the map's surface than
  /// a tracked scan (min_inlier_fraction): at a wrong place in a town of blocks alike, the
  /// block beside the sensor fits (half of what it sees) and the rest does not; a tracked
  /// scan has its last pose to vouch for it, a first fix nothing.
  double search_extra_inliers = 0.1;
  /// ... and of its points on upright surfaces (walls, posts, trunks), at least this many
  /// where the map observed anything, and this share of them on the map's surface. The
  /// ground fits at a wrong place as well as at the right one; what stands on it does not.
  /// In a map of a 247 m stretch of the town loop a walk that starts 44 m outside it was once
  /// taken for a street of the map that looks like its own (turned by 90 deg, a crossing
  /// ahead and one behind) and tracked there for 23 s: 67 % of its level points (median) lay
  /// on the map's surface there, more than at the right place in the whole loop's map (32 %:
  /// ground the map saw from 40 m), but 53-64 % of its upright ones; scans at their right place, in
  /// the whole loop's map and in that stretch, had 66-93 % of their upright points on it (the
  /// lowest where the map saw those walls only from 40 m and more), a walk's and a drive's
  /// 1 % lowest 72 % and more.
  size_t search_min_upright_points = 50;
  double search_min_upright_inliers = 0.7;
  /// A search keyframe none of whose descriptor's places holds is laid over the whole map
  /// seen from above (slam::loops::MapLayout), and this many of the best places there are
  /// checked: a sensor that starts on a street the map saw only from a crossing, or tens of
  /// metres from the nearest keyframe, is proposed no place near it by a descriptor.
  /// 0: descriptors alone.
  size_t search_layout_places = 4;
  /// A place found from scratch is checked against the map keyframes' points too where the
  /// map's surface has nothing (it holds what lay within the local map around the path, the
  /// keyframes what the sensor saw out to its range): a sensor that starts on a street the
  /// mapping run looked down from afar is found there, then confirmed on the surface by the
  /// tracking, which uses the surface alone (the points far from their keyframe are a few
  /// centimetres less sure).
  bool search_keyframe_points = true;

  static slam::refine::VgicpSettings tracking_vgicp();
};

LocalizerSettings localizer_from_config(const config::Config& config);

/// One scan's answer.
struct LocalizedScan {
  uint64_t sequence = 0;
  int64_t stamp_ns = 0;
  LocalizeStatus status = LocalizeStatus::kLost;
  /// The sensor's pose in the map at the stamp; none while lost.
  std::optional<Eigen::Isometry3d> T_map_sensor;
  /// The registration to the map, where one was made: its fit at the result.
  bool registered = false;
  double fitness_m = 0.0;
  /// Of its points where the map observed anything, the share on the map's surface.
  double inlier_fraction = 0.0;
  double coverage = 0.0;  ///< the share of its points where the map observed anything
  /// How firmly the points on the surface hold the pose: its standard deviation along the
  /// direction (about the axis) they constrain least; infinite where they leave one free.
  double position_sigma_m = 0.0;
  double rotation_sigma_deg = 0.0;
  /// How far the map's own surfaces may have moved it (MapFit::surface_position_m).
  double surface_position_m = 0.0;
  double surface_rotation_deg = 0.0;
  int iterations = 0;
  double ms = 0.0;  ///< add_scan's time
  /// What changed at this scan, for the log ("localized: ...", "lost: ..."); mostly empty.
  std::string event;
};

/// Where the sensor was first found, and how.
struct LocalizationFix {
  size_t scan = 0;  ///< scans given before it
  int64_t stamp_ns = 0;
  std::string found_by;  ///< "descriptor", "layout", "guess" or "earlier match"
  double descriptor_distance = 1.0;
  double fitness_m = 0.0;  ///< the check against the map's surface
  double inlier_fraction = 0.0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

struct LocalizerCounts {
  size_t scans = 0;
  std::map<std::string, size_t> by_status;  ///< to_string(status) -> scans
  size_t fixes = 0;                         ///< times found (the first and after each loss)
  std::map<std::string, size_t> losses;     ///< by reason
  size_t unconfirmed_matches = 0;           ///< keyframe matches the map's surface did not confirm
  std::optional<LocalizationFix> first_fix;
  std::vector<double> tracking_ms;  ///< per scan registered while localized or on odometry
  /// Parts of the tracking, per scan: the odometry (while it runs), the scan's cloud, the
  /// registrations to the map.
  std::vector<double> odometry_ms;
  std::vector<double> cloud_ms;
  std::vector<double> register_ms;
  size_t points_per_scan_sum = 0;
  std::vector<double> search_ms;  ///< per scan while lost
  /// The search's keyframes matched against the map's, the candidates they had, those the
  /// registration to the map keyframe verified, and why the others placed nothing.
  size_t search_keyframes = 0;
  size_t search_candidates = 0;
  size_t search_verified = 0;
  std::map<std::string, size_t> search_rejected;
  /// The map from above (the layout search's): the time to make it and its size.
  double layout_ms = 0.0;
  size_t layout_bytes = 0;
  std::vector<double> layout_search_ms;  ///< per search keyframe
  /// The map keyframes' points beyond the surface (the search's): the time to gather them
  /// and their size.
  double keyframe_points_ms = 0.0;
  size_t keyframe_points_bytes = 0;
  size_t map_keyframes = 0;
  size_t map_chunks = 0;
  /// The map's surface: chunks read, reused, the cache's bytes.
  size_t chunks_made = 0;
  size_t chunks_reused = 0;
  size_t chunks_evicted = 0;
  size_t peak_cache_bytes = 0;
  double chunk_read_ms = 0.0;
  double chunk_cells_ms = 0.0;
  /// The targets made around the sensor, and the time tracking waited for them.
  size_t targets_built = 0;
  size_t targets_waited = 0;
  double target_build_ms = 0.0;
  double target_wait_ms = 0.0;
};

class Localizer {
 public:
  /// Opens `map` (a featsense map.h5) read-only and reads its keyframes. `initial_pose` (the
  /// first scan's pose in the map, a user's guess) narrows the first search to places within
  /// 10 m and 30 degrees of it, as the odometry carries it; each is verified like every match.
  /// Throws std::runtime_error naming the file and the problem (missing, corrupt, no
  /// keyframes), config::ConfigError where the configuration sets another voxel size than the
  /// map's.
  Localizer(const std::filesystem::path& map, const config::Config& config,
            const std::optional<Eigen::Isometry3d>& initial_pose = std::nullopt);
  ~Localizer();
  Localizer(const Localizer&) = delete;
  Localizer& operator=(const Localizer&) = delete;

  LocalizedScan add_scan(const slam::Scan& scan);

  LocalizerCounts counts() const;
  const LocalizerSettings& settings() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace featsense::mapping
