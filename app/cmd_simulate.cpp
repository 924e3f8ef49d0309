// featsense simulate: a spinning LiDAR moving through a built-in scene or a mesh file,
// written as a recording folder (sequence.yaml + PCD frames) or as the sensor's packets in a
// pcap, with its ground truth.

#include <spdlog/spdlog.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/slam/io/pcap_recorders.hpp"
#include "featsense/slam/io/scan_writers.hpp"
#include "featsense/slam/sim/lidar_simulator.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/sim/simulation_writer.hpp"
#include "featsense/viewer_export/assimp_mesh_io.hpp"
#include "progress.hpp"
#include "simulate_job.hpp"

namespace featsense::app {
namespace {

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw slam::WriteError(path.string() + ": cannot write");
}

}  // namespace

slam::SimulationRequest simulation_request(const SimulateOptions& o) {
  slam::SimulationRequest request;
  request.scene = o.scene;
  if (!slam::is_builtin_scene(o.scene) && std::filesystem::exists(o.scene)) {
    viewer_export::AssimpReadOptions load;
    load.unit_scale = o.unit_scale;
    load.up_axis = o.up_axis;
    load.surfaces_only = true;
    request.scene_mesh = viewer_export::read_mesh_with_assimp(o.scene, nullptr, load);
  }
  request.path = o.path;
  request.trajectory_file = o.trajectory_file;
  request.sensor = o.sensor;
  if (o.format == "velodyne-pcap") {
    // A Velodyne's packets say what it fired, so the simulator fires the same grid.
    try {
      request.sensor_model = slam::velodyne_firing_sensor(o.sensor, o.rate_hz);
    } catch (const config::ConfigError& e) {
      throw config::ConfigError(std::string("--format velodyne-pcap: ") + e.what());
    }
  }
  request.rate_hz = o.rate_hz;
  request.measurement.seed = o.seed;
  request.measurement.range_noise = !o.no_noise;
  request.measurement.intensity = !o.no_intensity;
  request.measurement.dropouts = !o.no_dropouts;
  request.measurement.mixed_pixels = !o.no_mixed_pixels;
  request.frames = o.frames;
  if (o.stop.size() == 2) {
    request.stop_at_s = o.stop[0];
    request.stop_for_s = o.stop[1];
  }
  return request;
}

void run_simulate(const SimulateOptions& o, const CliContext& context) {
  context.load_config();  // validates --config / --set even though nothing here reads them
  std::optional<tbb::global_control> threads;
  if (o.threads > 0)
    threads.emplace(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(o.threads));
  const slam::PreparedSimulation prepared(simulation_request(o));
  const slam::LidarSimulator& simulator = *prepared.simulator;
  const slam::SimulationSettings& settings = simulator.settings();
  const mesh::TriangleMesh& mesh = prepared.mesh;
  const uint64_t frames = prepared.frames;
  const slam::PoseCurve* trajectory = prepared.trajectory.get();

  const bool to_folder = o.format == "folder";
  // Creates the folder, so it comes before the pcap.
  slam::SimulationWriter writer(o.output_dir, settings.sensor, 0.02, to_folder);
  std::unique_ptr<slam::OusterPcapRecorder> ouster;
  std::unique_ptr<slam::VelodynePcapRecorder> velodyne;
  const std::filesystem::path pcap_path = std::filesystem::path(o.output_dir) / "recording.pcap";
  if (o.format == "ouster-pcap") {
    ouster = std::make_unique<slam::OusterPcapRecorder>(pcap_path.string(), settings.sensor);
    write_text(std::filesystem::path(o.output_dir) / "recording.json", ouster->metadata_json());
  } else if (o.format == "velodyne-pcap") {
    velodyne = std::make_unique<slam::VelodynePcapRecorder>(pcap_path.string(), o.sensor,
                                                            settings.sensor.rate_hz);
  }
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
    if (ouster) ouster->add(frame.scan);
    if (velodyne) velodyne->add(frame.scan);
    progress.update(i + 1);
  }
  writer.finish(mesh);
  if (ouster) {
    ouster->finish();
    spdlog::info("{}: {} lidar and {} IMU packets (metadata in recording.json)", pcap_path.string(),
                 ouster->lidar_packets(), ouster->imu_packets());
  }
  if (velodyne) {
    velodyne->finish();
    spdlog::info("{}: {} Velodyne data packets", pcap_path.string(), velodyne->packets());
  }
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
                   "Built-in scene (lab, parking, corridor, town, town-changed, city) or a mesh "
                   "file (PLY, OBJ, "
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
  command
      ->add_option("--stop", o->stop,
                   "AT,FOR: the sensor brakes to a stand where the path is at AT seconds, "
                   "stands FOR seconds and goes on (a stop at a crossing, a pause)")
      ->expected(2)
      ->delimiter(',')
      ->check(CLI::NonNegativeNumber);
  command->add_option("--rate", o->rate_hz, "Revolutions per second (default: the sensor's)")
      ->check(CLI::Range(0.1, 100.0));
  command->add_option("--seed", o->seed, "Seed of the measurement noise")->capture_default_str();
  command->add_option("--unit-scale", o->unit_scale, "Mesh coordinates times this are metres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--up-axis", o->up_axis, "Up axis of the mesh file: auto, y or z")
      ->check(CLI::IsMember({"auto", "y", "z"}))
      ->capture_default_str();
  command
      ->add_option("--format", o->format,
                   "What the frames are written as: folder (sequence.yaml and PCD frames), "
                   "ouster-pcap (recording.pcap of an Ouster's lidar and IMU packets, with its "
                   "metadata in recording.json), or velodyne-pcap (recording.pcap of a "
                   "Velodyne's data packets; --sensor hdl32, vlp32c or vlp16)")
      ->check(CLI::IsMember({"folder", "ouster-pcap", "velodyne-pcap"}))
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
