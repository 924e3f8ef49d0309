#pragma once
// One pass over a recording: each scan placed by the front end (given poses or odometry),
// its pose refined, offered to the loop closure, turned into rays and integrated into the
// TSDF map, which spills into the store. Each stage is a method of its own so that the
// threaded pipeline (map_pipeline.hpp) runs them in threads joined by bounded queues and the
// synchronous Mapper::add_scan one after the other: both make the same map. Every stage is
// called from one thread only (its own), in scan order.

#include <atomic>
#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "featsense/config/config.hpp"
#include "featsense/mapping/loop_stage.hpp"
#include "featsense/mapping/map_preview.hpp"
#include "featsense/mapping/map_sessions.hpp"
#include "featsense/mapping/pass_result.hpp"
#include "featsense/mapping/reintegration_plan.hpp"
#include "featsense/mapping/run_events.hpp"
#include "featsense/mapping/scan_latency.hpp"
#include "featsense/slam/loops/loop_closer.hpp"
#include "featsense/slam/refine/placement_refiner.hpp"
#include "featsense/slam/scan.hpp"
#include "featsense/slam/scan_locator.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/tsdf/ray_batch.hpp"

namespace featsense::mapping {

/// Where a pass writes: a new map file (replaced with `overwrite`), or a copy of a map being
/// continued (in place where it is the same file).
struct MapStoreRequest {
  std::filesystem::path path;
  std::string sensor_name;
  std::optional<std::string> continue_from;
  bool overwrite = false;
  /// The run as the map's new session (map_sessions.hpp).
  SessionDescription session;
  /// The keyframes the session keeps; null: those of this pass's loop closure, where it ran.
  const std::vector<slam::loops::KeyframeRecord>* keyframes = nullptr;
};

/// What a pass does with each scan besides placing it.
struct PassSettings {
  double flush_interval_s = config::MapConfig{}.flush_interval_s;     ///< map.flush_interval
  bool drop_mixed_pixels = config::SensorConfig{}.drop_mixed_pixels;  ///< sensor.drop_mixed_pixels
  /// Refine the locator's poses before they are mapped (refine.*; for odometry).
  std::optional<slam::refine::RefineSettings> refine;
  /// Close loops over the final poses (loop.*; for odometry): keyframes, verification, the
  /// pose graph in a thread of their own; the corrected poses come with the result.
  std::optional<slam::loops::LoopSettings> loops;
  /// With loops: place the run in a saved map as its keyframes come.
  std::optional<RelocalizeStage> relocalize;
  /// False: the poses only, nothing integrated and no store opened.
  bool integrate = true;
  /// A live source: the pipeline's real-time policy (map_pipeline.hpp) keeps the odometry at
  /// the sensor's pace; the loop closure skips keyframes rather than wait.
  bool real_time = false;
  /// The map as it is made, re-meshed where it changed about every interval (map_preview.hpp);
  /// none: no preview.
  std::optional<MapPreviewSettings> preview;
  /// Poses corrected: only these scans are integrated again, each with the local map where a
  /// full re-map would have it (reintegration_plan.hpp); the others keep their poses only.
  /// Null: every scan, the local map following the sensor. Must outlive the pass.
  const ScanReintegration* reintegrate = nullptr;
};

/// map.flush_interval and sensor.drop_mixed_pixels of `config`: a pass that integrates, with
/// neither refinement nor loops (the Mapper adds those where they run).
PassSettings pass_settings(const config::Config& config);

/// A scan with its place, on its way to becoming rays.
struct PlacedScan {
  slam::Scan scan;
  slam::ScanPlacement placement;
};

/// A placed scan as rays in the map frame: what the mapping stage integrates.
struct LocatedScan {
  slam::ScanPlacement placement;
  tsdf::RayBatch rays;
  /// False: the real-time policy skipped its integration (no rays); its pose is kept.
  bool integrate = true;
};

/// Why the real-time policy dropped a whole scan before the odometry.
enum class ScanDrop { kOdometryBehind, kRefinementBehind };

class PreviewMesher;

class MapPass {
 public:
  /// Opens the store of `store` (not with settings.integrate false); `config` holds a
  /// continued map's voxel size and tau already (with_continued_geometry). `sensor` gives the
  /// TSDF its beams (vertical interpolation). `locator` and `config` must outlive the pass.
  MapPass(slam::ScanLocator& locator, const PassSettings& settings, const config::Config& config,
          const config::SensorModel& sensor, const MapStoreRequest& store, RunEvents events);
  ~MapPass();
  MapPass(const MapPass&) = delete;
  MapPass& operator=(const MapPass&) = delete;

  /// The reader's stage: every scan the source handed out is counted; one before the range
  /// to map is counted apart, one that goes on to be mapped with the time it took to read.
  void count_read() { frames_read_.fetch_add(1); }
  void count_before_range() { ++result_.frames_outside_range; }
  void add_read_time(double read_ms) { result_.timings.read_ms.push_back(read_ms); }
  /// Scan `sequence` was handed out now: its latencies count from here (a scan given to
  /// locate() without this counts from that call).
  void mark_ready(uint64_t sequence) { latency_.ready(sequence); }
  /// The reader's stage, real time: a scan dropped unplaced (thread-safe).
  void count_dropped(uint64_t sequence, ScanDrop why);
  bool real_time() const { return settings_.real_time; }
  /// Whether the pass holds scans for a refinement (the pipeline gives it a thread).
  bool refines() const { return refiner_ != nullptr; }
  /// The recording's scans, where known: for the progress only.
  void set_total_frames(std::optional<size_t> frames) { total_frames_ = frames; }
  bool stop_requested() const { return events_.stop.stop_requested(); }

  /// The front end: mixed pixels dropped, the scan placed. Nullopt: skipped (counted, warned).
  std::optional<PlacedScan> locate(slam::Scan scan, std::string* why = nullptr);
  /// The refinement: the scans whose poses became final, in order (at once without it).
  /// `behind` (the real-time policy): the refinement makes no cloud of this scan.
  std::vector<PlacedScan> refine(PlacedScan placed, bool behind = false);
  /// The end of the input (or a stop): the last stretch refined (nothing the second time).
  std::vector<PlacedScan> finish_refinement();
  /// The loop closure sees the scan; its rays are made (not with `skip_integration`: the
  /// real-time policy's choice, its pose only goes on). Nullopt: the run stops (the
  /// relocalization gave up, or the loop thread was abandoned).
  std::optional<LocatedScan> make_rays(PlacedScan placed, bool skip_integration = false);
  /// Integrated into the map (the local map follows the sensor; flushed every
  /// flush_interval_s), or, without a map, its pose kept.
  void integrate(LocatedScan located);

  /// The source's warnings, after the pass's own.
  void add_source_warnings(const slam::ReadStats& read);

  /// A failure somewhere: the loop thread is stopped and what was integrated is flushed.
  /// Never throws.
  void abandon();
  /// The end: the loop closure finishes, the map is flushed, the poses and the session go
  /// into the store. Call once, after every stage is done.
  PassResult close();

  /// The loop closure's stage (null without one), for a bench after close().
  LoopStage* loop_stage() { return loops_.get(); }

  /// Results of the stages so far; read only from the thread that calls integrate().
  const PassResult& result() const { return result_; }

 private:
  void warn(const std::string& message);
  void open_map(const LocatedScan& first);
  void report_progress();
  void update_preview(bool last);
  std::vector<PlacedScan> release(std::vector<slam::ScanPlacement> final);
  void write_store();

  slam::ScanLocator& locator_;
  PassSettings settings_;
  const config::Config& config_;
  config::SensorModel sensor_;
  MapStoreRequest request_;
  RunEvents events_;
  PassResult result_;
  std::mutex warnings_mutex_;
  std::atomic<size_t> frames_read_{0};
  std::atomic<size_t> dropped_odometry_behind_{0};
  std::atomic<size_t> dropped_refinement_behind_{0};
  ScanLatency latency_;
  std::unique_ptr<slam::refine::PlacementRefiner> refiner_;
  std::deque<PlacedScan> held_;  ///< scans waiting for their final pose, in order
  bool refinement_finished_ = false;
  std::unique_ptr<LoopStage> loops_;
  struct Store;
  std::unique_ptr<Store> store_;
  std::optional<size_t> total_frames_;
  std::unique_ptr<PreviewMesher> preview_;
  /// The front end's latest pose, for the preview (written by locate(), read by integrate()).
  struct LatestPose {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    int64_t stamp_ns = 0;
    bool known = false;
    double latency_ms = std::nan("");
  };
  std::mutex latest_mutex_;
  LatestPose latest_;
  double integration_latency_ms_ = std::nan("");
  std::chrono::steady_clock::time_point started_;
  std::chrono::steady_clock::time_point last_flush_;
  bool closed_ = false;
};

}  // namespace featsense::mapping
