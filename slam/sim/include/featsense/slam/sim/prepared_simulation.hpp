#pragma once
/// One simulation set up and checked: the scene, the sensor's path and the simulator, ready to
/// produce frames (for `featsense simulate`, `demo` and the front-end benchmarks).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "featsense/config/sensor_model.hpp"
#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/measurement_model.hpp"
#include "featsense/slam/sim/ray_caster.hpp"
#include "featsense/slam/sim/trajectory.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"

namespace featsense::slam {

struct SimulationRequest {
  /// A built-in scene's name (scene_library.hpp), or what `scene_mesh` is called in messages.
  std::string scene;
  /// A scene loaded from a mesh file; unset: the built-in scene `scene`.
  std::optional<mesh::TriangleMesh> scene_mesh;
  /// A named path of the built-in scene (walk, drive, drone, loop); empty: walk, unless
  /// `trajectory_file` is given.
  std::string path;
  std::string trajectory_file;     ///< TUM sensor poses (map <- sensor) instead of `path`
  std::string sensor = "os1-128";  ///< a preset, or an Ouster metadata .json
  /// The sensor itself, where it is made rather than named (the firing grid of a Velodyne
  /// whose packets are written: velodyne_firing_sensor); set, `sensor` is not read. Such a
  /// model holds for its rate: leave rate_hz 0 or at that rate.
  std::optional<config::SensorModel> sensor_model;
  double rate_hz = 0.0;             ///< revolutions per second; 0: the sensor's
  MeasurementSettings measurement;  ///< noise, intensity, drop-outs, mixed pixels
  int frames = 0;                   ///< 0: as many as the path holds
  /// A stop on the path (make_paused_trajectory): the sensor stands `stop_for_s` seconds
  /// where the path is at `stop_at_s`, braking and starting at 1.5 m/s^2 at most. 0: none.
  double stop_at_s = 0.0;
  double stop_for_s = 0.0;
};

struct PreparedSimulation {
  /// Throws InputError, TrajectoryError or std::invalid_argument naming the problem: an
  /// unknown scene, both or neither of a path and poses where one is needed, a path shorter
  /// than a revolution or than `frames`, a path outside the scene.
  explicit PreparedSimulation(SimulationRequest request);
  // The simulator refers to the mesh, caster and trajectory held here: never move them.
  PreparedSimulation(const PreparedSimulation&) = delete;
  PreparedSimulation& operator=(const PreparedSimulation&) = delete;

  mesh::TriangleMesh mesh;
  std::unique_ptr<PoseCurve> trajectory;
  std::unique_ptr<RayCaster> caster;
  std::unique_ptr<LidarSimulator> simulator;
  uint64_t frames = 0;  ///< the request's frames, or all that the path holds

  /// The true pose of each frame at its stamp (column 0's time), as gt_trajectory.tum holds.
  Trajectory frame_poses() const;
};

}  // namespace featsense::slam
