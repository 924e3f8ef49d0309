#pragma once
// One simulation as a function, for `featsense simulate` and `featsense demo`.

#include <cstdint>
#include <string>
#include <vector>

#include "cli_context.hpp"
#include "featsense/slam/sim/prepared_simulation.hpp"

namespace featsense::app {

struct SimulateOptions {
  std::string scene;
  std::string output_dir;
  std::string sensor = "os1-128";
  std::string path;
  std::string trajectory_file;
  int frames = 0;  ///< 0: as many as the trajectory holds
  double rate_hz = 0.0;
  /// --stop AT,FOR: stand FOR seconds where the path is at AT seconds; empty: no stop.
  std::vector<double> stop;
  uint64_t seed = 1;
  double unit_scale = 1.0;
  std::string up_axis = "auto";
  bool no_noise = false;
  bool no_intensity = false;
  bool no_dropouts = false;
  bool no_mixed_pixels = false;
  int threads = 0;  ///< 0: all cores
  /// What the frames are written as: "folder" (sequence.yaml + PCD frames + imu.csv),
  /// "ouster-pcap" (recording.pcap of the sensor's packets + recording.json, its metadata), or
  /// "velodyne-pcap" (recording.pcap of the data packets of the Velodyne preset `sensor`,
  /// which then fires its own grid: velodyne_firing_sensor).
  std::string format = "folder";
};

/// What `o` asks to simulate, its scene loaded where it is a mesh file (assimp: unit scale,
/// up axis, surfaces only). Throws InputError for a scene that is neither a file nor a
/// built-in scene's name.
slam::SimulationRequest simulation_request(const SimulateOptions& o);

/// Simulates the scene into o.output_dir (the frames in o.format, ground truth). Throws
/// ConfigError, InputError or std::runtime_error.
void run_simulate(const SimulateOptions& o, const CliContext& context);

}  // namespace featsense::app
