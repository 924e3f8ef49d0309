#pragma once
// The mapping engine behind one small facade: a Mapper is made from its settings (and
// optionally a saved map to continue), takes scans one at a time with add_scan() (or from a
// ScanSource through the threaded pipeline, map_pipeline.hpp, which runs the same stages in
// threads of their own and makes the same map), and finish() closes the loops, maps the
// recording again with the corrected poses where its input can be read again, writes the
// store and returns what the run did.
//
//   featsense::mapping::MapperSettings settings;
//   settings.sensor = source->info().sensor;
//   settings.map_path = "out/map.h5";
//   featsense::mapping::Mapper mapper(settings);
//   while (std::optional<featsense::slam::Scan> scan = source->next()) mapper.add_scan(*scan);
//   const featsense::mapping::MapResult result = mapper.finish();

#include <Eigen/Geometry>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "featsense/config/config.hpp"
#include "featsense/mapping/map_pass.hpp"
#include "featsense/mapping/map_pipeline.hpp"
#include "featsense/mapping/map_policy.hpp"
#include "featsense/mapping/map_preview.hpp"
#include "featsense/mapping/pass_result.hpp"
#include "featsense/mapping/recording.hpp"
#include "featsense/mapping/relocalization_report.hpp"
#include "featsense/mapping/run_events.hpp"
#include "featsense/slam/odometry/odometry_locator.hpp"
#include "featsense/slam/scan.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::mapping {

struct MapperSettings {
  /// Every setting of the run (map.*, odometry.*, refine.*, loop.*, relocalize.*, sensor.*).
  config::Config config;
  /// The scans' sensor (beams and field of view for the TSDF's vertical interpolation): the
  /// source's SourceInfo::sensor.
  config::SensorModel sensor;
  /// The store written: a new file (an existing one is an error unless `overwrite`).
  std::filesystem::path map_path = "map.h5";
  bool overwrite = false;
  /// A saved map (.h5, or .vdb with given poses) that this run extends; its voxel size and
  /// tau win. Without given poses the recording is first placed in it by its keyframes.
  std::optional<std::string> continue_from;
  /// The sensor's poses in the map frame (TUM: interpolated to each column's time); none:
  /// the odometry estimates them.
  std::optional<slam::Trajectory> given_poses;
  /// The odometry's pose of the first scan in the map frame (not when continuing a map: a
  /// recording placed in a saved map starts in a frame of its own).
  Eigen::Isometry3d T_map_first_scan = Eigen::Isometry3d::Identity();
  /// Continuing without given poses: where the first scan lies in the map, roughly (still
  /// verified).
  std::optional<Eigen::Isometry3d> initial_guess;
  /// False: the poses only (odometry, refinement, loops), no store written.
  bool integrate = true;
  /// A live sensor: map_source() keeps the odometry at its pace by the real-time policy of
  /// map_pipeline.hpp (integrations skipped, then scans dropped, each counted).
  bool real_time = false;
  /// The map as it is made, for a person watching (map_preview.hpp): the first pass re-meshes
  /// the chunks that changed about every interval and hands them over. None: no preview.
  std::optional<MapPreviewSettings> preview;
  /// The run as the map's new session: its input, format and how its poses were placed.
  SessionDescription session;
  /// Reads the input again from its start, for the second pass (and, continuing, for the
  /// mapping pass after the placement); empty where it cannot be read twice.
  SourceReopener reopen;
  /// The scans of the input that were mapped: a second pass reads the same ones.
  FrameRange range;
};

/// What add_scan() did with a scan.
struct ScanUpdate {
  bool placed = false;            ///< false: skipped (why says why)
  std::string why;                ///< why it was skipped, or why its pose is not trusted
  slam::ScanPlacement placement;  ///< the front end's (before refinement and loops)
  size_t scans_mapped = 0;        ///< scans whose final pose is known and integrated so far
  bool stopped = false;           ///< the run has stopped taking scans (placing gave up)
};

struct MapResult {
  /// The configuration the map was made with (a continued map's voxel size and tau applied).
  config::Config config;
  /// The first pass: the front end's poses (continuing: in the recording's own frame).
  PassResult first;
  /// The pass that mapped again with the corrected poses (or, continuing, into the map).
  std::optional<PassResult> second;
  SecondPassOutcome second_pass;
  /// The poses of the map, one per mapped scan; with loops closed and no second pass, the
  /// corrected ones all the same (to map later with them as given poses).
  slam::Trajectory final_poses;
  std::string poses;  ///< where the poses came from, one line
  std::optional<slam::odometry::OdometryCounts> odometry;
  std::optional<slam::refine::RefineSettings> refine;  ///< the refinement's, where it ran
  std::string loops_off_because;                       ///< empty: loop closure ran
  std::optional<RelocalizationReport> relocalization;  ///< continuing without given poses

  /// The pass whose map was kept.
  const PassResult& mapped() const { return second ? *second : first; }
};

class Mapper {
 public:
  /// Opens the store (or, continuing without given poses, reads the saved map). Throws
  /// config::ConfigError or std::runtime_error naming what is wrong.
  explicit Mapper(MapperSettings settings, RunEvents events = {});
  ~Mapper();
  Mapper(const Mapper&) = delete;
  Mapper& operator=(const Mapper&) = delete;

  /// Places the next scan (in recording order) and integrates every scan whose pose became
  /// final. Synchronous: the scan is done with when it returns.
  ScanUpdate add_scan(slam::Scan scan);

  /// The scans integrated so far, at their final poses of this pass.
  const slam::Trajectory& poses() const;
  /// The first pass's counts and times so far.
  const PassResult& diagnostics() const;
  /// The front end: given poses or the odometry, in words.
  std::string front_end() const;
  /// Whether the odometry estimates the poses (else they are given).
  bool estimates_poses() const { return odometry_ != nullptr; }
  const std::optional<slam::refine::RefineSettings>& refine_settings() const;
  /// Why the loop closure does not run (empty: it does).
  const std::string& loops_off_because() const { return loops_off_because_; }
  /// The run's settings (a continued map's voxel size and tau applied to its config).
  const MapperSettings& settings() const { return settings_; }

  /// The first pass, for the threaded pipeline: run_pipeline(source, mapper.first_pass()).
  MapPass& first_pass();

  /// The end of the input: closes the loops, maps again where they corrected the poses,
  /// writes the store. Throws Interrupted (after writing what it had), RelocalizationFailed
  /// (continuing: the map untouched) or std::runtime_error.
  MapResult finish();

 private:
  class Continuation;
  MapResult finish_continuation(MapResult result);
  void second_pass(MapResult& result);
  void integrate_final(std::vector<PlacedScan> scans);

  MapperSettings settings_;
  RunEvents events_;
  std::unique_ptr<slam::odometry::OdometryLocator> odometry_;
  std::unique_ptr<slam::ScanLocator> given_;
  slam::ScanLocator* locator_ = nullptr;
  PassSettings pass_settings_;
  std::string loops_off_because_;
  std::unique_ptr<Continuation> continuation_;
  std::unique_ptr<MapPass> first_;
  bool stopped_ = false;
  bool finished_ = false;
};

/// Maps `source` (its scans in the settings' range) with `mapper` through the threaded
/// pipeline, then finishes it.
MapResult map_source(slam::ScanSource& source, Mapper& mapper);

}  // namespace featsense::mapping
