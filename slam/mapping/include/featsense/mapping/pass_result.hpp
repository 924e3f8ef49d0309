#pragma once
// What one pass over a recording did: its counts, its per-stage times, the poses it mapped
// with, what the refinement and the loop closure found, and what it wrote into the store.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "featsense/mapping/loop_stage.hpp"
#include "featsense/slam/refine/placement_refiner.hpp"
#include "featsense/slam/trajectory/scan_motions.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/storage/shifting_map.hpp"

namespace featsense::mapping {

/// Per-stage times of each scan, milliseconds.
struct StageTimings {
  std::vector<double> read_ms;
  std::vector<double> locate_ms;
  std::vector<double> refine_ms;  ///< the refinement stage per scan: its cloud, a registration
  std::vector<double> rays_ms;    ///< a placed scan turned into rays (deskewed, in the map frame)
  std::vector<double> shift_ms;
  std::vector<double> integrate_ms;
  std::vector<double> flush_ms;
  std::vector<double> final_flush_ms;
  /// The live preview's refreshes (map_preview.hpp) on the integrating thread: the changed
  /// chunks copied out (their meshing runs on a thread of its own).
  std::vector<double> preview_ms;
  double loops_finish_ms = 0.0;  ///< after the last scan: the keyframes left, the last solve
  /// Per scan, from when its source handed it out (a live sensor: about its last packet) to
  /// its pose from the front end, its final pose (after the refinement: the loop closure and
  /// the rays see it) and its integration into the map.
  std::vector<double> latency_pose_ms;
  std::vector<double> latency_final_pose_ms;
  std::vector<double> latency_integrated_ms;
};

/// What the real-time policy (map_pipeline.hpp; a live sensor) gave up so that the odometry
/// keeps the sensor's pace, by stage and reason.
struct RealTimeCounts {
  bool enabled = false;  ///< the pass ran under the policy
  /// Whole scans dropped before the odometry, unplaced: it was still busy with earlier ones,
  /// or the refinement held it up (its queue full).
  size_t scans_dropped_odometry_behind = 0;
  size_t scans_dropped_refinement_behind = 0;
  /// Scans placed (their poses kept) but not integrated: the TSDF was behind.
  size_t integrations_skipped = 0;
  /// Scans the refinement took without making their clouds: it was behind. A stretch left
  /// without clouds keeps the last stretch's correction instead of being registered.
  size_t refinement_clouds_skipped = 0;
  /// Keyframes the loop closure did not get: its thread was behind.
  size_t keyframes_skipped = 0;

  size_t scans_dropped() const {
    return scans_dropped_odometry_behind + scans_dropped_refinement_behind;
  }
};

struct PassResult {
  size_t frames_read = 0;  ///< scans the source handed out
  /// Scans integrated into the map (or placed, without a map); not those whose integration
  /// the real-time policy skipped (real_time.integrations_skipped), whose poses are kept.
  size_t frames_mapped = 0;
  /// Poses corrected (PassSettings::reintegrate): scans not integrated again, poses kept.
  size_t frames_not_reintegrated = 0;
  size_t frames_without_pose = 0;
  size_t frames_outside_range = 0;
  size_t points = 0;  ///< rays integrated
  size_t mixed_pixels_dropped = 0;
  size_t voxels_updated = 0;
  StageTimings timings;
  /// The pose of every mapped scan (and of every scan whose integration was skipped), at its
  /// stamp.
  slam::Trajectory poses;
  RealTimeCounts real_time;
  /// With refinement: the locator's poses before it, and what it did.
  std::optional<slam::Trajectory> unrefined_poses;
  slam::refine::RefineCounts refine;
  std::vector<double> refine_cloud_ms;  ///< per cloud made
  size_t refine_most_held = 0;          ///< the most scans waiting for their final pose
  std::optional<LoopOutcome> loops;     ///< with loop closure
  /// With loop closure: each scan's motion as placed, for the second pass.
  slam::ScanMotions scan_motions;
  size_t warning_count = 0;
  std::vector<std::string> warnings;  ///< the first few, verbatim
  bool interrupted = false;           ///< stopped by the caller's stop token
  double wall_s = 0.0;
  double recording_s = 0.0;  ///< time from the first to the last mapped scan's stamp

  // The store, where the pass integrated.
  std::string backend = "none";  ///< "cuda" or "cpu" once a scan was integrated
  std::string backend_reason;
  storage::ShiftingMapStats map;
  size_t map_chunks = 0;        ///< chunks in the store at the end
  size_t continued_chunks = 0;  ///< chunks of the map that was continued
  size_t device_memory_bytes = 0;

  double scans_per_s() const {
    return wall_s > 0.0 ? static_cast<double>(frames_mapped) / wall_s : 0.0;
  }
};

}  // namespace featsense::mapping
