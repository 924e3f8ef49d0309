// featsense demo: a built-in scene simulated, mapped with poses that the odometry estimates
// (or the true ones, --gt-poses), meshed and compared with the truth, in one command that
// needs nothing but the program.

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/sim/simulated_scan_source.hpp"
#include "map_job.hpp"
#include "simulate_job.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

struct DemoOptions {
  std::string output = "featsense-demo";
  std::string scene = "lab";
  std::string path = "walk";
  int frames = 0;         ///< 0: the whole path
  bool gt_poses = false;  ///< map with the true poses instead of the odometry's
  bool tiles = false;     ///< the mesh as a tile set (a city's route), not one mesh
  std::optional<std::string> backend;
  std::optional<double> plan_height;  ///< topdown.png's cut
};

std::string percent(const nlohmann::json& fraction) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f %%", 100.0 * fraction.get<double>());
  return text;
}

void print_summary(const DemoOptions& options, const MapOutcome& outcome) {
  const nlohmann::json& r = outcome.report;
  const fs::path& out = outcome.out;
  std::printf("featsense demo: the %s scene, %s path, a simulated %s\n", options.scene.c_str(),
              options.path.c_str(), r["input"]["sensor"].get<std::string>().c_str());
  std::printf("  mapped %d scans in %.1f s (%.1f scans/s, %s backend), %d map shifts\n",
              r["frames"].get<int>(), r["wall_s"].get<double>(), r["scans_per_s"].get<double>(),
              r["backend"].get<std::string>().c_str(), r["map"]["shifts"].get<int>());
  if (r.contains("mesh") && r["mesh"].contains("tiles")) {
    std::printf("  mesh: %zu triangles in %zu tiles\n", r["mesh"]["triangles"].get<size_t>(),
                r["mesh"]["tiles"]["tiles"].get<size_t>());
  } else if (r.contains("mesh")) {
    std::printf("  mesh: %zu triangles, %zu vertices\n", r["mesh"]["triangles"].get<size_t>(),
                r["mesh"]["vertices"].get<size_t>());
  }
  if (r.contains("eval") && r["eval"].contains("traj")) {
    const nlohmann::json& t = r["eval"]["traj"];
    std::printf(
        "  poses estimated by the odometry: ATE %.1f mm (RMSE over %d poses, %.1f m of path)\n",
        1e3 * t["ape"]["rmse"].get<double>(), t["ape"]["count"].get<int>(),
        t["ground_truth_length_m"].get<double>());
    if (r.contains("loops") && r["loops"].value("accepted", 0) > 0) {
      const nlohmann::json& loops = r["loops"];
      std::string before;
      if (r["eval"].contains("traj_before_loops")) {
        before = ": ATE before them " +
                 std::to_string(std::lround(
                     1e3 * r["eval"]["traj_before_loops"]["ape"]["rmse"].get<double>())) +
                 " mm; " + loops["second_pass"].get<std::string>();
      }
      std::printf("  %d loops closed (%d keyframes, %d candidates rejected)%s\n",
                  loops["accepted"].get<int>(), loops["keyframes"].get<int>(),
                  loops["candidates"].get<int>() - loops["accepted"].get<int>(), before.c_str());
    }
  } else {
    std::printf("  mapped with the true poses\n");
  }
  if (r.contains("eval") && r["eval"].contains("mesh")) {
    const nlohmann::json& e = r["eval"]["mesh"];
    std::printf(
        "  against the true surface: mean distance %.1f mm (median %.1f mm), completeness %s "
        "within 5 cm and %s within 10 cm of what the sensor saw\n",
        1e3 * e["accuracy"]["mean_abs"].get<double>(), 1e3 * e["accuracy"]["median"].get<double>(),
        percent(e["completeness"]["0.05"]).c_str(), percent(e["completeness"]["0.10"]).c_str());
    if (e.contains("aligned")) {
      const nlohmann::json& a = e["aligned"]["accuracy"];
      std::printf(
          "  aligned with the true path first (the map's own shape): mean %.1f mm, p95 %.1f mm\n",
          1e3 * a["mean_abs"].get<double>(), 1e3 * a["p95"].get<double>());
    }
  }
  std::printf("  files in %s:\n", out.string().c_str());
  for (const char* name : {"map.h5", "mesh.ply", "mesh.glb", "topdown.png", "mesh_error.ply",
                           "mesh_error.glb", "mesh_error.png", "trajectory_error.png",
                           "trajectory.tum", "report.json", "report.html", "tiles/tileset.json"}) {
    if (fs::exists(out / name)) std::printf("    %s\n", (out / name).string().c_str());
  }
  std::printf("    %s (the scene, the true path and the surface points the sensor saw)\n",
              (out / "ground_truth").string().c_str());
}

void run_demo(const DemoOptions& options, const CliContext& context) {
  MapOptions map;
  map.output = options.output;
  map.backend = options.backend;
  map.overwrite = true;  // the demo's own folder: a second demo replaces the first
  map.print_summary = false;
  map.plan_height = options.plan_height;
  map.tiles = options.tiles;
  // Bad --config / --set fail before the simulation.
  const config::Config config = map_config(map, context);
  SimulateOptions simulate;
  simulate.scene = options.scene;
  simulate.path = options.path;
  simulate.frames = options.frames;
  const slam::PreparedSimulation simulation(simulation_request(simulate));

  const fs::path out(options.output);
  const fs::path truth = out / "ground_truth";
  const std::string description = "built-in scene " + options.scene + ", " + options.path + " path";
  slam::SimulatedScanSource source(*simulation.simulator, simulation.mesh, *simulation.trajectory,
                                   simulation.frames, description, truth.string());

  MeshReferences references;
  references.surface = truth / "gt_mesh.ply";
  references.seen = truth / "gt_points.ply";
  // The true path is known: with estimated poses it fixes the map's frame at the first
  // pose and scores the odometry; with --gt-poses it is what the map is built with.
  const KnownTrajectory truth_path{simulation.frame_poses(), true};
  std::optional<slam::Trajectory> given;
  if (options.gt_poses) given = truth_path.poses;
  // The simulation runs again for the loop closure's second pass (the same scans: it is
  // deterministic).
  const SourceReopener reopen = [&]() -> std::unique_ptr<slam::ScanSource> {
    return std::make_unique<slam::SimulatedScanSource>(*simulation.simulator, simulation.mesh,
                                                       *simulation.trajectory, simulation.frames,
                                                       description, truth.string());
  };
  const MapOutcome outcome = map_recording(
      source, given, options.gt_poses ? std::nullopt : std::optional<KnownTrajectory>(truth_path),
      map, config, references, context, reopen);
  if (!context.quiet) print_summary(options, outcome);
}

}  // namespace

Command register_demo(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<DemoOptions>();
  CLI::App* command = app.add_subcommand(
      "demo", "Simulate a built-in scene, map it, mesh it and compare it with the truth");
  command->add_option("-o,--output", options->output, "Output folder")->capture_default_str();
  command
      ->add_option("--scene", options->scene,
                   "Built-in scene: lab, parking, corridor, town, town-changed or city")
      ->check(CLI::IsMember(slam::scene_names()))
      ->capture_default_str();
  // Which paths a scene has is the scene library's to say (an unknown one is an error that
  // lists them).
  command
      ->add_option("--path", options->path,
                   "The sensor's path: walk, drive, drone (lab, corridor, parking), loop "
                   "(parking, town), tour (city)")
      ->capture_default_str();
  command->add_option("--frames", options->frames, "Frames to simulate (default: the whole path)")
      ->check(CLI::Range(1, 100000));
  command->add_flag("--gt-poses", options->gt_poses,
                    "Map with the true poses instead of estimating them with the odometry");
  command->add_flag("--tiles", options->tiles,
                    "The mesh as a tile set (OUT/tiles/, 3D Tiles), made and compared with the "
                    "truth a tile at a time: for the city's routes");
  add_config_option(*command, kBackendOption, options->backend);
  add_plan_height_option(*command, options->plan_height);
  return {command, [options, &context] { run_demo(*options, context); }};
}

}  // namespace featsense::app
