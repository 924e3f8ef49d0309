#pragma once
// One simulation as a function, for `featsense simulate` and `featsense demo`.

#include <cstdint>
#include <memory>
#include <string>

#include "cli_context.hpp"
#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/ray_caster.hpp"
#include "featsense/slam/sim/trajectory.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::app {

struct SimulateOptions {
  std::string scene;
  std::string output_dir;
  std::string sensor = "os1-128";
  std::string path;
  std::string trajectory_file;
  int frames = 0;  ///< 0: as many as the trajectory holds
  double rate_hz = 0.0;
  uint64_t seed = 1;
  double unit_scale = 1.0;
  std::string up_axis = "auto";
  bool no_noise = false;
  bool no_intensity = false;
  bool no_dropouts = false;
  bool no_mixed_pixels = false;
  int threads = 0;  ///< 0: all cores
};

/// The scene, the sensor's path and the simulator of `o`, checked and ready to produce frames.
struct PreparedSimulation {
  /// Throws ConfigError, InputError or std::invalid_argument naming the problem.
  explicit PreparedSimulation(const SimulateOptions& o);
  // The simulator refers to the mesh, caster and trajectory held here: never move them.
  PreparedSimulation(const PreparedSimulation&) = delete;
  PreparedSimulation& operator=(const PreparedSimulation&) = delete;

  mesh::TriangleMesh mesh;
  std::unique_ptr<slam::PoseCurve> trajectory;
  std::unique_ptr<slam::RayCaster> caster;
  std::unique_ptr<slam::LidarSimulator> simulator;
  uint64_t frames = 0;  ///< o.frames, or all that the path holds

  /// The true pose of each frame at its stamp (column 0's time), as gt_trajectory.tum holds.
  slam::Trajectory frame_poses() const;
};

/// Simulates the scene into o.output_dir (sequence.yaml, frames, ground truth). Throws
/// ConfigError, InputError or std::runtime_error.
void run_simulate(const SimulateOptions& o, const CliContext& context);

}  // namespace featsense::app
