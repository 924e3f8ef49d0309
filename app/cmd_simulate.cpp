// featsense simulate: a spinning LiDAR moving through a built-in scene or a mesh file,
// written as a recording folder (sequence.yaml + PCD frames) with its ground truth.

#include <spdlog/spdlog.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "commands.hpp"
#include "featsense/config/sensor_model.hpp"
#include "featsense/slam/io/ouster_metadata.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/ray_caster.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/sim/simulation_writer.hpp"
#include "featsense/slam/sim/trajectory.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "featsense/viewer_export/assimp_mesh_io.hpp"
#include "progress.hpp"
#include "simulate_job.hpp"

namespace featsense::app {
namespace {

/// A preset by name, or the sensor of an Ouster metadata JSON file (per-beam angles, beam
/// origin offset, columns and rate of that unit).
config::SensorModel sensor_model(const std::string& name_or_file) {
  if (std::filesystem::path(name_or_file).extension() != ".json")
    return config::sensor_preset(name_or_file);
  std::ifstream in(name_or_file, std::ios::binary);
  if (!in) throw slam::InputError(name_or_file + ": cannot read the sensor metadata");
  std::ostringstream text;
  text << in.rdbuf();
  return slam::parse_ouster_metadata(text.str(), name_or_file).sensor_model();
}

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

/// The sensor's path; `start_stamp_ns` is set to the TUM file's first time, so that the
/// frames and gt_trajectory.tum share the file's clock.
std::unique_ptr<slam::PoseCurve> make_trajectory(const SimulateOptions& o, bool builtin,
                                                 int64_t* start_stamp_ns) {
  if (!o.trajectory_file.empty()) {
    const std::vector<slam::StampedPose> poses =
        slam::to_stamped_poses(slam::read_tum(o.trajectory_file));
    if (poses.size() < 2) {
      throw slam::TrajectoryError(o.trajectory_file + ": a trajectory needs at least two poses");
    }
    *start_stamp_ns = static_cast<int64_t>(std::llround(poses.front().t_s * 1e9));
    return slam::make_sampled_trajectory(poses);
  }
  if (!builtin)
    throw std::invalid_argument(
        "a scene mesh needs --trajectory FILE (named paths belong to "
        "the built-in scenes)");
  const slam::NamedPath path = slam::scene_path(o.scene, o.path.empty() ? "walk" : o.path);
  return slam::make_spline_trajectory(path.waypoints_m, path.speed_mps, path.tilt);
}

}  // namespace

PreparedSimulation::PreparedSimulation(const SimulateOptions& o) {
  if (!o.path.empty() && !o.trajectory_file.empty())
    throw std::invalid_argument("give --path or --trajectory, not both");
  const bool builtin = slam::is_builtin_scene(o.scene);
  if (!builtin && !std::filesystem::exists(o.scene)) {
    std::string names;
    for (const std::string& name : slam::scene_names()) names += (names.empty() ? "" : ", ") + name;
    throw slam::InputError(o.scene + ": no such mesh file, and no built-in scene of that name (" +
                           names + ")");
  }
  viewer_export::AssimpReadOptions load;
  load.unit_scale = o.unit_scale;
  load.up_axis = o.up_axis;
  load.surfaces_only = true;
  mesh = builtin ? slam::build_scene(o.scene)
                 : viewer_export::read_mesh_with_assimp(o.scene, nullptr, load);
  slam::SimulationSettings settings;
  trajectory = make_trajectory(o, builtin, &settings.start_stamp_ns);

  settings.sensor = sensor_model(o.sensor);
  if (o.rate_hz > 0.0) settings.sensor.rate_hz = o.rate_hz;
  settings.measurement.seed = o.seed;
  settings.measurement.range_noise = !o.no_noise;
  settings.measurement.intensity = !o.no_intensity;
  settings.measurement.dropouts = !o.no_dropouts;
  settings.measurement.mixed_pixels = !o.no_mixed_pixels;

  caster = std::make_unique<slam::RayCaster>(mesh);
  simulator = std::make_unique<slam::LidarSimulator>(mesh, *caster, *trajectory, settings);
  const uint64_t available = simulator->frames_available();
  if (available == 0)
    throw std::invalid_argument("the trajectory lasts " + std::to_string(trajectory->duration_s()) +
                                " s, shorter than one revolution");
  if (o.frames > 0 && static_cast<uint64_t>(o.frames) > available)
    throw std::invalid_argument("the trajectory lasts " + std::to_string(trajectory->duration_s()) +
                                " s: room for " + std::to_string(available) + " frames, not " +
                                std::to_string(o.frames));
  frames = o.frames > 0 ? static_cast<uint64_t>(o.frames) : available;
  // A little room around the scene: a drone above a roofless house or a walker at the edge
  // of a ground quad is fine; a path in the wrong units or frame is far off and still caught.
  constexpr double kMarginM = 2.0;
  slam::check_trajectory_inside(
      *trajectory, mesh, static_cast<double>(frames) / settings.sensor.rate_hz, 0.01, kMarginM);
}

slam::Trajectory PreparedSimulation::frame_poses() const {
  const slam::SimulationSettings& settings = simulator->settings();
  slam::Trajectory poses;
  for (uint64_t i = 0; i < frames; ++i) {
    const double t = static_cast<double>(i) / settings.sensor.rate_hz;
    poses.push_back(settings.start_stamp_ns + static_cast<int64_t>(std::llround(t * 1e9)),
                    trajectory->pose(t));
  }
  return poses;
}

void run_simulate(const SimulateOptions& o, const CliContext& context) {
  context.load_config();  // validates --config / --set even though nothing here reads them
  std::optional<tbb::global_control> threads;
  if (o.threads > 0)
    threads.emplace(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(o.threads));
  const PreparedSimulation prepared(o);
  const slam::LidarSimulator& simulator = *prepared.simulator;
  const slam::SimulationSettings& settings = simulator.settings();
  const mesh::TriangleMesh& mesh = prepared.mesh;
  const uint64_t frames = prepared.frames;
  const slam::PoseCurve* trajectory = prepared.trajectory.get();

  slam::SimulationWriter writer(o.output_dir, settings.sensor);
  Progress progress("frames", frames, context.quiet);
  std::vector<double> frame_ms;
  // CPU time of the calling thread: with --threads 1 the whole cost of a frame, free of what
  // other processes on a busy machine take (wall time is not).
  double cpu_ms = 0.0;
  for (uint64_t i = 0; i < frames; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = thread_cpu_ms();
    const slam::SimulatedFrame frame = simulator.simulate(i);
    cpu_ms += thread_cpu_ms() - cpu_start;
    frame_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    writer.add(frame, trajectory->pose(frame.start_s));
    progress.update(i + 1);
  }
  writer.finish(mesh);
  progress.finish();
  std::sort(frame_ms.begin(), frame_ms.end());
  const double median_ms = frame_ms[frame_ms.size() / 2];
  const double rays = static_cast<double>(settings.sensor.beams) * settings.sensor.columns;
  spdlog::info(
      "simulated {} frames of {} x {} ({} triangles) into {}: {:.1f} ms per frame (median), "
      "{:.2f} Mrays/s, {:.1f} ms of CPU time per frame in this thread; {} ground-truth points",
      frames, settings.sensor.beams, settings.sensor.columns, mesh.triangle_count(), o.output_dir,
      median_ms, rays / median_ms * 1e-3, cpu_ms / static_cast<double>(frames),
      writer.ground_truth_points());
}

Command register_simulate(CLI::App& app, const CliContext& context) {
  auto o = std::make_shared<SimulateOptions>();
  CLI::App* command = app.add_subcommand(
      "simulate", "Simulate a spinning LiDAR in a built-in scene or a mesh, with ground truth");
  command
      ->add_option("--scene", o->scene,
                   "Built-in scene (lab, parking, corridor, town) or a mesh file (PLY, OBJ, "
                   "glTF/GLB, DAE, STL)")
      ->required();
  command->add_option("-o,--output", o->output_dir, "Folder for the recording")->required();
  command->add_option("--sensor", o->sensor, "Sensor preset, or an Ouster metadata .json")
      ->capture_default_str();
  command->add_option("--path", o->path,
                      "Named path of a built-in scene: walk, drive, drone (lab, corridor, "
                      "parking), loop (parking, town); default walk");
  command->add_option("--trajectory", o->trajectory_file,
                      "TUM file of sensor poses (map <- sensor)");
  command->add_option("--frames", o->frames, "Frames to simulate (default: the whole path)")
      ->check(CLI::PositiveNumber);
  command->add_option("--rate", o->rate_hz, "Revolutions per second (default: the sensor's)")
      ->check(CLI::Range(0.1, 100.0));
  command->add_option("--seed", o->seed, "Seed of the measurement noise")->capture_default_str();
  command->add_option("--unit-scale", o->unit_scale, "Mesh coordinates times this are metres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--up-axis", o->up_axis, "Up axis of the mesh file: auto, y or z")
      ->check(CLI::IsMember({"auto", "y", "z"}))
      ->capture_default_str();
  command->add_option("--threads", o->threads, "Worker threads (default: all cores)")
      ->check(CLI::PositiveNumber);
  command->add_flag("--no-noise", o->no_noise, "Exact ranges (no range noise)");
  command->add_flag("--no-intensity", o->no_intensity,
                    "Intensity is the material reflectance (no range / incidence falloff)");
  command->add_flag("--no-dropouts", o->no_dropouts, "Keep grazing, dark and weak returns");
  command->add_flag("--no-mixed-pixels", o->no_mixed_pixels, "No mixed pixels at depth edges");
  return {command, [o, &context] { run_simulate(*o, context); }};
}

}  // namespace featsense::app
