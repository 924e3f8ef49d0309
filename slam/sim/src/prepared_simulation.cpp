#include "featsense/slam/sim/prepared_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/ouster_metadata.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"

namespace featsense::slam {
namespace {

/// A preset by name, or the sensor of an Ouster metadata JSON file (per-beam angles, beam
/// origin offset, columns and rate of that unit).
config::SensorModel sensor_model(const std::string& name_or_file) {
  if (std::filesystem::path(name_or_file).extension() != ".json")
    return config::sensor_preset(name_or_file);
  std::ifstream in(name_or_file, std::ios::binary);
  if (!in) throw InputError(name_or_file + ": cannot read the sensor metadata");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_ouster_metadata(text.str(), name_or_file).sensor_model();
}

/// The sensor's path; `start_stamp_ns` is set to the TUM file's first time, so that the
/// frames and gt_trajectory.tum share the file's clock.
std::unique_ptr<PoseCurve> make_trajectory(const SimulationRequest& request, bool builtin,
                                           int64_t* start_stamp_ns) {
  if (!request.trajectory_file.empty()) {
    const std::vector<StampedPose> poses = to_stamped_poses(read_tum(request.trajectory_file));
    if (poses.size() < 2) {
      throw TrajectoryError(request.trajectory_file + ": a trajectory needs at least two poses");
    }
    *start_stamp_ns = static_cast<int64_t>(std::llround(poses.front().t_s * 1e9));
    return make_sampled_trajectory(poses);
  }
  if (!builtin)
    throw std::invalid_argument(
        "a scene mesh needs --trajectory FILE (named paths belong to "
        "the built-in scenes)");
  const NamedPath path = scene_path(request.scene, request.path.empty() ? "walk" : request.path);
  return make_spline_trajectory(path.waypoints_m, path.speed_mps, path.tilt);
}

/// The gentlest braking a stop uses, m/s^2: a car braking for a crossing, a walker pausing.
constexpr double kStopDeceleration = 1.5;

/// `path` with the request's stop, if any: the ramp lasts as long as braking from the speed
/// the path has there takes (a half-cosine profile peaks at pi/2 times the mean deceleration),
/// at least a second.
std::unique_ptr<PoseCurve> with_stop(std::unique_ptr<PoseCurve> path,
                                     const SimulationRequest& request) {
  if (request.stop_for_s <= 0.0 && request.stop_at_s <= 0.0) return path;
  constexpr double kPi = 3.14159265358979323846;
  const double at_s = request.stop_at_s;
  const double before_s = std::max(at_s - 0.2, 0.0);
  const double speed_mps =
      at_s > before_s
          ? (path->pose(at_s).translation() - path->pose(before_s).translation()).norm() /
                (at_s - before_s)
          : 0.0;
  const double ramp_s = std::max(1.0, kPi * speed_mps / (2.0 * kStopDeceleration));
  return make_paused_trajectory(std::move(path), at_s + 0.5 * ramp_s, request.stop_for_s, ramp_s);
}

}  // namespace

PreparedSimulation::PreparedSimulation(SimulationRequest request) {
  if (!request.path.empty() && !request.trajectory_file.empty())
    throw std::invalid_argument("give --path or --trajectory, not both");
  const bool builtin = !request.scene_mesh;
  if (builtin && !is_builtin_scene(request.scene)) {
    std::string names;
    for (const std::string& name : scene_names()) names += (names.empty() ? "" : ", ") + name;
    throw InputError(request.scene + ": no such mesh file, and no built-in scene of that name (" +
                     names + ")");
  }
  mesh = builtin ? build_scene(request.scene) : std::move(*request.scene_mesh);
  SimulationSettings settings;
  trajectory = with_stop(make_trajectory(request, builtin, &settings.start_stamp_ns), request);
  settings.sensor = request.sensor_model ? *request.sensor_model : sensor_model(request.sensor);
  if (request.rate_hz > 0.0) settings.sensor.rate_hz = request.rate_hz;
  settings.measurement = request.measurement;

  caster = std::make_unique<RayCaster>(mesh);
  simulator = std::make_unique<LidarSimulator>(mesh, *caster, *trajectory, settings);
  const uint64_t available = simulator->frames_available();
  if (available == 0)
    throw std::invalid_argument("the trajectory lasts " + std::to_string(trajectory->duration_s()) +
                                " s, shorter than one revolution");
  if (request.frames > 0 && static_cast<uint64_t>(request.frames) > available)
    throw std::invalid_argument("the trajectory lasts " + std::to_string(trajectory->duration_s()) +
                                " s: room for " + std::to_string(available) + " frames, not " +
                                std::to_string(request.frames));
  frames = request.frames > 0 ? static_cast<uint64_t>(request.frames) : available;
  // A little room around the scene: a drone above a roofless house or a walker at the edge
  // of a ground quad is fine; a path in the wrong units or frame is far off and still caught.
  constexpr double kMarginM = 2.0;
  check_trajectory_inside(*trajectory, mesh, static_cast<double>(frames) / settings.sensor.rate_hz,
                          0.01, kMarginM);
}

Trajectory PreparedSimulation::frame_poses() const {
  const SimulationSettings& settings = simulator->settings();
  Trajectory poses;
  for (uint64_t i = 0; i < frames; ++i) {
    const double t = static_cast<double>(i) / settings.sensor.rate_hz;
    poses.push_back(settings.start_stamp_ns + static_cast<int64_t>(std::llround(t * 1e9)),
                    trajectory->pose(t));
  }
  return poses;
}

}  // namespace featsense::slam
