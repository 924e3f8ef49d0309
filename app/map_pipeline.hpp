#pragma once
// The mapping pipeline: a reader thread, a front-end thread (the scan locator), with odometry a
// refinement thread (slam/refine: the poses made final a stretch at a time), a thread that
// turns placed scans into rays (and hands keyframes to the loop closure's thread) and a
// mapping thread (shift, TSDF integration, periodic flush of the store), joined by bounded
// queues.
// A full queue makes the stage before it wait, so memory stays bounded however fast the
// reader is; a failing stage stops the others and its error is rethrown after all joined.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/refine/placement_refiner.hpp"
#include "featsense/slam/scan_locator.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/trajectory/scan_motions.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/storage/shifting_map.hpp"
#include "featsense/tsdf/ray_batch.hpp"
#include "loop_stage.hpp"

namespace featsense::app {

/// Which scans of the recording to map: frame indices (0-based, as scan.sequence) and/or
/// seconds after the first scan; both ends inclusive.
struct FrameRange {
  std::optional<uint64_t> first_frame;
  std::optional<uint64_t> last_frame;
  std::optional<double> first_s;
  std::optional<double> last_s;
  /// Stamps (the scans' clock): a session of a map mapped again keeps to its own scans.
  std::optional<int64_t> first_stamp_ns;
  std::optional<int64_t> last_stamp_ns;
};

/// A scan placed by the front end and turned into rays (app/scan_to_rays.hpp): what the
/// mapping thread integrates.
struct LocatedScan {
  slam::ScanPlacement placement;
  tsdf::RayBatch rays;
};

struct PipelineSettings {
  size_t queue_capacity = 4;                                       ///< scans per queue
  double flush_interval_s = config::MapConfig{}.flush_interval_s;  ///< map.flush_interval
  FrameRange range;
  std::optional<size_t> total_frames;  ///< for the progress display, when known
  bool drop_mixed_pixels = true;       ///< sensor.drop_mixed_pixels
  /// Refine the locator's poses before they are mapped (refine.*; for odometry).
  std::optional<slam::refine::RefineSettings> refine;
  /// Close loops over the final poses (loop.*; for odometry): keyframes, verification, the
  /// pose graph in a thread of their own; the corrected poses come with the result.
  std::optional<slam::loops::LoopSettings> loops;
  /// With loops: relocalize the run in a saved map as its keyframes come (`map --continue`
  /// without poses).
  std::optional<RelocalizeStage> relocalize;
  /// False: the poses only, nothing integrated (`map --poses-only`); the map opener is not
  /// called.
  bool integrate = true;
  bool quiet = false;
};

/// Per-stage times of each scan, milliseconds.
struct StageTimings {
  std::vector<double> read_ms;
  std::vector<double> locate_ms;
  std::vector<double> refine_ms;  ///< the refinement stage per scan: its cloud, a registration
  std::vector<double> rays_ms;    ///< a placed scan turned into rays (deskewed, in the map frame)
  std::vector<double> shift_ms;
  std::vector<double> integrate_ms;
  std::vector<double> flush_ms;
  double loops_finish_ms = 0.0;  ///< after the last scan: the keyframes left, the last solve
};

struct PipelineResult {
  size_t frames_read = 0;    ///< scans the source handed out
  size_t frames_mapped = 0;  ///< scans integrated into the map
  size_t frames_without_pose = 0;
  size_t frames_outside_range = 0;
  size_t points = 0;  ///< rays integrated
  size_t mixed_pixels_dropped = 0;
  size_t voxels_updated = 0;
  StageTimings timings;
  slam::Trajectory poses;  ///< the pose of every mapped scan, at its stamp
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
  bool interrupted = false;           ///< stopped by Ctrl+C / SIGTERM
  double wall_s = 0.0;
  double recording_s = 0.0;  ///< time from the first to the last mapped scan's stamp
};

/// Creates the local map (centred on the first located scan) and ties it to the store; called
/// once, from the mapping thread.
using MapOpener = std::function<storage::ShiftingMap&(const LocatedScan& first)>;

/// Runs the pipeline until the source ends, the range ends or a stop signal arrives. The
/// caller syncs the map afterwards (also when this throws: what was integrated is in the map).
PipelineResult run_map_pipeline(slam::ScanSource& source, slam::ScanLocator& locator,
                                const MapOpener& open_map, const PipelineSettings& settings);

}  // namespace featsense::app
