#pragma once
// One mapping run as a function, for `featsense map` and `featsense demo`.

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "cli_context.hpp"
#include "featsense/mapping/map_preview.hpp"
#include "featsense/mapping/recording.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "map_outputs.hpp"
#include "source_options.hpp"
#include "stop_signal.hpp"

namespace featsense::app {

struct MapOptions {
  InputOptions input;
  std::string output;
  std::optional<std::string> gt;
  std::string gt_format = "auto";
  std::optional<std::string> gt_times;
  std::optional<std::string> backend;
  std::optional<std::string> continue_from;
  std::optional<std::string> initial_pose;  ///< x,y,z,yaw_deg of the first scan in the map
  std::optional<std::string> start;
  std::optional<std::string> end;
  std::optional<std::string> reference;
  std::optional<std::string> reference_trajectory;  ///< the true path, for eval.traj
  std::optional<double> plan_height;  ///< topdown.png's cut, map frame z; default: the path's
  bool overwrite = false;
  bool no_mesh = false;
  bool tiles = false;            ///< the mesh as a tile set (OUT/tiles/), not one mesh.ply
  bool no_loop_closure = false;  ///< loop.enabled false
  bool poses_only = false;       ///< the poses and the report, no map
  bool print_summary = true;     ///< the one-line summary on stdout
  bool real_time = false;        ///< a live sensor: the pipeline's real-time policy
  /// The map as it is made (`live --view`): the first pass's refreshes go to its deliver.
  std::optional<mapping::MapPreviewSettings> preview;
};

struct MapOutcome {
  std::filesystem::path out;
  nlohmann::json report;  ///< as written to report.json
};

/// Adds --overwrite, --no-mesh, --tiles and --no-loop-closure (MapOptions') to `command`.
void add_map_output_flags(CLI::App& command, MapOptions& options);

/// The true path where it is known, for the report's eval.traj (SE(3)-aligned, as `featsense
/// eval traj`). A simulation's starts at the first scan: estimated poses then start there too,
/// so that the map lies in the frame of the true surface and compares with it unaligned.
struct KnownTrajectory {
  slam::Trajectory poses;
  bool starts_at_first_scan = false;
};

/// Maps INPUT (opened with the run's configuration) into OUT, with the poses of --gt or,
/// without it, poses estimated by the odometry.
MapOutcome run_map(const MapOptions& options, const CliContext& context);

/// The run's configuration (defaults, --config, --set) with --backend applied. Throws
/// ConfigError.
config::Config map_config(const MapOptions& options, const CliContext& context);

/// Opens the recording again from its start, for the loop closure's second pass; empty where
/// the input cannot be read twice.
using SourceReopener = mapping::SourceReopener;

/// Maps `source` with `poses` (given poses; nullopt: estimated by the odometry front end) and
/// `config` (from map_config) into OUT (map.h5, trajectory.tum/.kitti, mesh.ply/.glb,
/// report.json), comparing the path with `truth` where given. Ctrl+C stops it through
/// `stop_signal` where given (one the caller installed, that its source also heeds), else
/// through one of its own. Throws ConfigError, InputError, Interrupted (after writing the
/// outputs) or std::runtime_error.
MapOutcome map_recording(slam::ScanSource& source, std::optional<slam::Trajectory> poses,
                         const std::optional<KnownTrajectory>& truth, const MapOptions& options,
                         config::Config config, const MeshReferences& references,
                         const CliContext& context, const SourceReopener& reopen = {},
                         const StopSignal* stop_signal = nullptr);

}  // namespace featsense::app
