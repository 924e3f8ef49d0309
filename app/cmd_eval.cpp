// featsense eval traj | mesh | maps: figures of a trajectory or mesh against ground truth, and
// two maps compared voxel by voxel.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "eval_json.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/mesh/region_comparison.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/storage/map_comparison.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"
#include "featsense/viewer_export/surface_file_regions.hpp"
#include "json_output.hpp"
#include "mesh_error_files.hpp"

namespace featsense::app {
namespace {

struct EvalTrajOptions {
  std::string estimate;
  std::string ground_truth;
  std::string format = "auto";
  std::string align = "se3";
  double max_diff_s = 0.01;
  double offset_s = 0.0;
  std::optional<std::string> estimate_times;
  std::optional<std::string> ground_truth_times;
  std::optional<std::string> json_path;
  std::optional<std::string> aligned_path;
};

struct EvalMeshOptions {
  std::string estimate;
  std::string reference;
  double max_dist_m = 0.0;
  double samples_per_m2 = mesh::CompareSettings{}.samples_per_m2;
  std::optional<std::string> json_path;
  std::optional<std::string> ply_path;
};

struct EvalMapsOptions {
  std::string first;
  std::string second;
  std::optional<std::string> json_path;
};

void emit(const nlohmann::json& json, const std::optional<std::string>& path,
          const std::string& text) {
  if (path) write_json(json, *path);
  if (path != "-") std::cout << text;
}

slam::Trajectory read_trajectory(const std::string& path, const std::string& format,
                                 const std::optional<std::string>& times) {
  if (times && format == "tum") {
    throw config::ConfigError("--est-times / --gt-times go with KITTI poses, not --format tum");
  }
  return slam::read_trajectory(path, format, times);
}

void run_traj(const EvalTrajOptions& options) {
  const slam::Trajectory estimate =
      read_trajectory(options.estimate, options.format, options.estimate_times);
  const slam::Trajectory ground_truth =
      read_trajectory(options.ground_truth, options.format, options.ground_truth_times);
  slam::TrajectoryEvaluationSettings settings;
  settings.alignment = slam::parse_alignment(options.align);
  settings.association.max_diff_s = options.max_diff_s;
  settings.association.offset_s = options.offset_s;
  const slam::TrajectoryEvaluation evaluation =
      slam::evaluate_trajectory(estimate, ground_truth, settings);
  if (options.aligned_path) slam::write_tum(evaluation.aligned_estimate, *options.aligned_path);
  nlohmann::json json = trajectory_evaluation_json(evaluation, settings);
  json["estimate"] = options.estimate;
  json["ground_truth"] = options.ground_truth;
  json["estimate_poses"] = estimate.size();
  json["ground_truth_poses"] = ground_truth.size();
  // Few pairs usually mean a clock offset or a rate mismatch rather than a short overlap.
  if (2 * evaluation.association.size() < std::min(estimate.size(), ground_truth.size())) {
    spdlog::warn("only {} of {} poses paired: check --t-offset and --max-diff",
                 evaluation.association.size(), std::min(estimate.size(), ground_truth.size()));
  }

  char line[256];
  std::string text;
  std::snprintf(line, sizeof line, "pairs:  %zu of %zu estimated and %zu ground-truth poses\n",
                evaluation.association.size(), estimate.size(), ground_truth.size());
  text += line;
  const slam::ErrorStatistics& a = evaluation.ape;
  std::snprintf(line, sizeof line,
                "APE:    rmse %.4f m, mean %.4f, median %.4f, std %.4f, min %.4f, max %.4f\n",
                a.rmse, a.mean, a.median, a.std, a.min, a.max);
  text += line;
  const slam::ErrorStatistics& r = evaluation.rpe_translation;
  std::snprintf(line, sizeof line,
                "RPE:    per frame rmse %.4f m, mean %.4f; rotation mean %.4f deg\n", r.rmse,
                r.mean, evaluation.rpe_rotation_deg.mean);
  text += line;
  if (evaluation.kitti) {
    std::snprintf(line, sizeof line, "KITTI:  %.3f %% translation, %.5f deg/m (%zu segments)\n",
                  evaluation.kitti->t_err_pct, evaluation.kitti->r_err_deg_per_m,
                  evaluation.kitti->segments);
  } else {
    std::snprintf(line, sizeof line, "KITTI:  path %.1f m, shorter than the 100 m segments\n",
                  evaluation.ground_truth_length_m);
  }
  text += line;
  emit(json, options.json_path, text);
}

/// MESH or REFERENCE by what it is: a tile set's folder, a tiled point file, a mesh file.
std::unique_ptr<mesh::SurfaceRegions> open_surface(const std::string& path,
                                                   const std::string& what) {
  try {
    return viewer_export::open_surface_regions(path);
  } catch (const std::exception& e) {
    throw std::runtime_error(what + ": " + e.what());
  }
}

void run_mesh(const EvalMeshOptions& options) {
  if (options.ply_path && viewer_export::is_tile_set(options.estimate)) {
    throw std::runtime_error("--ply-out colours one mesh; " + options.estimate +
                             " is a tile set (compare a tile's PLY for the picture)");
  }
  // Read a region at a time (mesh/region_comparison.hpp): a tile set or a simulator's dense
  // truth is never whole in memory; the figures are those of the whole comparison.
  const std::unique_ptr<mesh::SurfaceRegions> estimate = open_surface(options.estimate, "MESH");
  const std::unique_ptr<mesh::SurfaceRegions> reference =
      open_surface(options.reference, "REFERENCE");
  mesh::CompareSettings settings;
  settings.max_dist_m = options.max_dist_m;
  settings.samples_per_m2 = options.samples_per_m2;
  mesh::RegionComparisonSettings regions;
  regions.keep_distances = options.ply_path.has_value();  // else the figures alone
  mesh::CompareResult result;
  try {
    result = mesh::compare_by_region(*estimate, *reference, settings, regions);
  } catch (const mesh::MeshError& e) {
    throw std::runtime_error(options.estimate + " vs " + options.reference + ": " + e.what());
  }
  if (options.ply_path) {
    viewer_export::write_ply_mesh(*options.ply_path, viewer_export::read_mesh(options.estimate),
                                  distance_layers(result));
  }
  nlohmann::json json = mesh_comparison_json(result, settings);
  json["estimate"] = options.estimate;
  json["reference_file"] = options.reference;

  char line[256];
  std::string text;
  const mesh::DistanceStatistics& a = result.accuracy;
  std::snprintf(line, sizeof line, "points:       %zu (%zu beyond --max-dist)\n", result.points,
                result.beyond_max_dist);
  text += line;
  std::snprintf(line, sizeof line,
                "accuracy:     mean |d| %.4f m, mean %.4f, std %.4f, rmse %.4f, median %.4f, p95 "
                "%.4f, max %.4f\n",
                a.mean_abs, a.mean_signed, a.std_signed, a.rmse, a.median, a.p95, a.max);
  text += line;
  for (const mesh::ThresholdScores& s : result.scores) {
    std::snprintf(line, sizeof line,
                  "within %.2f m: completeness %.4f, precision %.4f, F-score %.4f\n", s.threshold_m,
                  s.completeness, s.precision, s.fscore);
    text += line;
  }
  emit(json, options.json_path, text);
}

void run_maps(const EvalMapsOptions& options) {
  storage::Hdf5ChunkStore first(options.first);
  storage::Hdf5ChunkStore second(options.second);
  const storage::MapDifference d = storage::compare_maps(first, second);
  const nlohmann::json json = {{"identical", d.identical()},
                               {"chunks_equal", d.chunks_equal},
                               {"chunks_differing", d.chunks_differing},
                               {"chunks_only_first", d.chunks_only_first},
                               {"chunks_only_second", d.chunks_only_second},
                               {"voxels_differing", d.voxels_differing},
                               {"voxels_observed_in_one", d.voxels_observed_in_one},
                               {"largest_value_difference_m", d.largest_value_difference_m},
                               {"largest_weight_difference", d.largest_weight_difference}};
  char text[400];
  std::snprintf(text, sizeof text,
                "%s: %zu chunks equal, %zu differing (%zu voxels, %zu observed in one only; "
                "values up to %.4f m, weights up to %.2f apart), %zu only in the first, %zu only "
                "in the second\n",
                d.identical() ? "identical" : "different", d.chunks_equal, d.chunks_differing,
                d.voxels_differing, d.voxels_observed_in_one, d.largest_value_difference_m,
                d.largest_weight_difference, d.chunks_only_first, d.chunks_only_second);
  emit(json, options.json_path, text);
}

}  // namespace

std::vector<Command> register_eval(CLI::App& app, const CliContext& /*context*/) {
  CLI::App* eval =
      app.add_subcommand("eval", "Compare a trajectory or a mesh with ground truth, or two maps");
  eval->require_subcommand(1);

  auto traj_options = std::make_shared<EvalTrajOptions>();
  CLI::App* traj = eval->add_subcommand(
      "traj", "Trajectory vs ground truth: APE, per-frame RPE, KITTI segment errors");
  traj->add_option("EST", traj_options->estimate, "Estimated trajectory")->required();
  traj->add_option("GT", traj_options->ground_truth, "Ground-truth trajectory")->required();
  traj->add_option("--format", traj_options->format,
                   "File format of each: auto (from the content), tum, or kitti (no stamps: "
                   "paired by index)")
      ->check(CLI::IsMember({"auto", "tum", "kitti"}))
      ->capture_default_str();
  traj->add_option("--align", traj_options->align, "Umeyama alignment: se3, se3-scale or none")
      ->check(CLI::IsMember({"se3", "se3-scale", "none"}))
      ->capture_default_str();
  traj->add_option("--max-diff", traj_options->max_diff_s,
                   "Largest stamp difference of a pose pair, seconds")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  traj->add_option("--t-offset", traj_options->offset_s,
                   "Added to the estimate's stamps before pairing (as evo's --t_offset), seconds")
      ->capture_default_str();
  traj->add_option("--est-times", traj_options->estimate_times,
                   "KITTI: the estimate's times file (seconds, one a line); else paired by index");
  traj->add_option("--gt-times", traj_options->ground_truth_times,
                   "KITTI: the ground truth's times file (seconds, one a line)");
  traj->add_option("--json", traj_options->json_path, "Write the figures as JSON ('-' = stdout)");
  traj->add_option("--aligned-out", traj_options->aligned_path,
                   "Write the paired, aligned estimate as TUM");

  auto mesh_options = std::make_shared<EvalMeshOptions>();
  CLI::App* mesh_command = eval->add_subcommand(
      "mesh", "Mesh vs reference mesh or cloud: cloud-to-mesh accuracy, completeness, F-score");
  mesh_command
      ->add_option("MESH", mesh_options->estimate,
                   "Estimated mesh (PLY, OBJ, glTF) or a tile set's folder (mesh --tiles)")
      ->required();
  mesh_command
      ->add_option("REFERENCE", mesh_options->reference,
                   "Reference mesh or point cloud (PLY, OBJ, glTF; a simulator's gt_points.ply "
                   "is read a tile at a time)")
      ->required();
  mesh_command
      ->add_option("--max-dist", mesh_options->max_dist_m,
                   "Leave points farther than this out of the accuracy figures, metres")
      ->check(CLI::NonNegativeNumber);
  mesh_command
      ->add_option("--samples-per-m2", mesh_options->samples_per_m2,
                   "Samples of a reference mesh for completeness, per square metre")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  mesh_command->add_option("--json", mesh_options->json_path,
                           "Write the figures as JSON ('-' = stdout)");
  mesh_command->add_option("--ply-out", mesh_options->ply_path,
                           "Write the mesh with scalar_distance and scalar_signed_distance");

  auto maps_options = std::make_shared<EvalMapsOptions>();
  CLI::App* maps = eval->add_subcommand(
      "maps", "Two maps (.h5) of one grid compared chunk by chunk and voxel by voxel");
  maps->add_option("FIRST", maps_options->first, "A map file (map.h5)")
      ->required()
      ->check(CLI::ExistingFile);
  maps->add_option("SECOND", maps_options->second,
                   "Another map file of the same voxel size and tau")
      ->required()
      ->check(CLI::ExistingFile);
  maps->add_option("--json", maps_options->json_path, "Write the figures as JSON ('-' = stdout)");

  return {{traj, [traj_options] { run_traj(*traj_options); }},
          {mesh_command, [mesh_options] { run_mesh(*mesh_options); }},
          {maps, [maps_options] { run_maps(*maps_options); }}};
}

}  // namespace featsense::app
