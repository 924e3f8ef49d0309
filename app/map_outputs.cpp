#include "map_outputs.hpp"

#include <chrono>
#include <cmath>
#include <memory>

#include "eval_json.hpp"
#include "featsense/mesh/compare_to_reference.hpp"
#include "featsense/mesh/region_comparison.hpp"
#include "featsense/mesh/surface_regions.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"
#include "featsense/viewer_export/plan_view.hpp"
#include "featsense/viewer_export/surface_file_regions.hpp"
#include "mesh_error_files.hpp"
#include "mesh_tile_set.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

}  // namespace

void add_plan_height_option(CLI::App& command, std::optional<double>& height_m) {
  command
      .add_option("--plan-height", height_m,
                  "Cut the plan view (topdown.png) at this height, metres, map frame (default: "
                  "0.3 m above the path near each place; without a path, 1.5 m above the floor "
                  "where there is a ceiling)")
      ->check(CLI::Number);
}

viewer_export::PlanPath plan_path(const slam::Trajectory& trajectory,
                                  viewer_export::PlanPath::Kind kind, const std::string& label) {
  viewer_export::PlanPath path;
  path.kind = kind;
  path.label = label;
  path.positions_m.reserve(trajectory.size());
  for (const Eigen::Isometry3d& T_map_sensor : trajectory.poses)
    path.positions_m.push_back(T_map_sensor.translation());
  return path;
}

MapMesh mesh_map(const fs::path& map_path, const fs::path& out, const PlanInputs& plan) {
  MapMesh result;
  storage::StoreSettings store_settings;
  store_settings.cache_bytes = std::size_t{128} << 20;
  storage::Hdf5ChunkStore store(map_path, store_settings);
  result.mesh = mesh::extract_mesh(store, mesh::MeshingSettings{}, &result.stats);
  if (result.mesh.triangles.empty()) return result;  // nothing observed twice over: no file
  const Clock::time_point start = Clock::now();
  viewer_export::write_mesh((out / "mesh.ply").string(), result.mesh);
  viewer_export::write_mesh((out / "mesh.glb").string(), result.mesh);
  const fs::path plan_file = out / "topdown.png";
  result.plan = viewer_export::write_plan_view_png(result.mesh, plan.paths, plan_file.string(),
                                                   plan.settings);
  result.write_s = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

MapMesh mesh_map_tiles(const fs::path& map_path, const fs::path& out, const PlanInputs& plan,
                       bool quiet) {
  MapMesh result;
  storage::StoreSettings store_settings;
  store_settings.cache_bytes = std::size_t{128} << 20;
  storage::Hdf5ChunkStore store(map_path, store_settings);
  if (store.keys().empty()) return result;
  viewer_export::TileSetSettings settings;
  settings.overview_triangles = kOverviewTriangles;
  viewer_export::TileSetReport report;
  result.tiles =
      write_tile_set_with_progress(store, (out / "tiles").string(), settings, quiet, &report);
  result.stats.chunks = report.chunks;
  result.stats.triangles = report.triangles;
  result.stats.vertices = report.vertices;
  result.stats.seconds = report.meshing_seconds;
  result.mesh = std::move(report.overview);
  result.overview_level = report.overview_level;
  if (result.mesh.triangles.empty()) return result;
  const Clock::time_point start = Clock::now();
  result.plan = viewer_export::write_plan_view_png(result.mesh, plan.paths,
                                                   (out / "topdown.png").string(), plan.settings);
  result.write_s = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

nlohmann::json mesh_json(const MapMesh& result) {
  const double s = result.stats.seconds;
  nlohmann::json json = {
      {"vertices", result.stats.vertices},
      {"triangles", result.stats.triangles},
      {"chunks", result.stats.chunks},
      {"seconds", s},
      {"triangles_per_s", s > 0.0 ? static_cast<double>(result.stats.triangles) / s : 0.0},
      {"write_s", result.write_s}};
  if (result.plan) json["plan"] = plan_json(*result.plan, "topdown.png");
  if (result.tiles) {
    json["tiles"] = *result.tiles;
    json["overview_level"] = result.overview_level;
  }
  return json;
}

nlohmann::json plan_json(const viewer_export::PlanView& plan, const std::string& file) {
  const auto height = [](double z) { return std::isfinite(z) ? nlohmann::json(z) : nullptr; };
  return {{"file", file},
          {"width_px", plan.width_px},
          {"height_px", plan.height_px},
          {"pixel_size_m", plan.pixel_size_m},
          {"grid_spacing_m", plan.grid_spacing_m},
          {"cut", plan.cut_rule},
          {"cut_low_m", height(plan.cut_low_m)},
          {"cut_high_m", height(plan.cut_high_m)}};
}

std::optional<fs::path> simulation_truth_folder(const std::string& input) {
  if (input.empty()) return std::nullopt;
  const fs::path path(input);
  std::error_code ec;
  if (fs::is_directory(path, ec)) return path;
  // A pcap alone in a folder with the simulator's truth: both files, so that a capture of
  // one's own kept beside some other trajectory is not taken for a simulation.
  const fs::path folder = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  if (path.extension() == ".pcap" && fs::is_regular_file(folder / "gt_trajectory.tum", ec) &&
      fs::is_regular_file(folder / "gt_mesh.ply", ec)) {
    return folder;
  }
  return std::nullopt;
}

MeshReferences find_mesh_references(const std::string& input,
                                    const std::optional<std::string>& user_reference) {
  MeshReferences references;
  if (user_reference) {
    references.surface = fs::path(*user_reference);
    return references;
  }
  const std::optional<fs::path> folder = simulation_truth_folder(input);
  if (folder && fs::is_regular_file(*folder / "gt_mesh.ply")) {
    references.surface = *folder / "gt_mesh.ply";
    if (fs::is_regular_file(*folder / "gt_points.ply")) references.seen = *folder / "gt_points.ply";
  }
  return references;
}

namespace {

/// The evaluation of `estimate` (see evaluate_map_mesh), a region at a time; the distances
/// to the surface in `against_surface` where given.
nlohmann::json evaluate_by_region(const mesh::SurfaceRegions& estimate,
                                  const MeshReferences& references,
                                  const std::optional<Eigen::Isometry3d>& T_truth_estimate,
                                  mesh::CompareResult* against_surface_out) {
  const mesh::CompareSettings settings;
  const bool seen = references.seen && fs::is_regular_file(*references.seen);
  const std::unique_ptr<mesh::SurfaceRegions> surface =
      viewer_export::open_surface_regions(*references.surface);
  mesh::RegionComparisonSettings regions;
  regions.completeness = !seen;  // else measured against what the sensor saw, below
  // The per-vertex distances only where a mesh is coloured by them: a tile set's are as many
  // as its vertices (35 M floats twice for 2.5 km of city).
  regions.keep_distances = against_surface_out != nullptr;
  mesh::CompareResult against_surface =
      mesh::compare_by_region(estimate, *surface, settings, regions);
  regions.keep_distances = false;
  nlohmann::json json = mesh_comparison_json(against_surface, settings);
  json["reference_file"] = references.surface->string();
  if (T_truth_estimate) {
    // The reference moved into the map's frame: the same distances as the mesh moved onto
    // the truth, for a fraction of the vertices.
    const mesh::MovedRegions moved(*surface, T_truth_estimate->inverse());
    regions.completeness = false;
    const mesh::CompareResult aligned = mesh::compare_by_region(estimate, moved, settings, regions);
    json["aligned"] = {{"by", "the estimated trajectory's SE(3) alignment to the true one"},
                       {"accuracy", mesh_comparison_json(aligned, settings)["accuracy"]}};
  }
  if (seen) {
    // Completeness counts only what the sensor saw: the points behind its returns (the
    // simulator's, in tiles: read a tile at a time).
    const std::unique_ptr<mesh::SurfaceRegions> seen_points =
        viewer_export::open_surface_regions(*references.seen);
    regions.accuracy = false;
    regions.completeness = true;
    const mesh::CompareResult against_seen =
        mesh::compare_by_region(estimate, *seen_points, settings, regions);
    json["completeness"] = mesh_comparison_json(against_seen, settings)["completeness"];
    for (auto& [key, precision] : json["precision"].items()) {
      const double p = precision.get<double>();
      const double c = json["completeness"][key].get<double>();
      json["fscore"][key] = p + c > 0.0 ? 2.0 * p * c / (p + c) : 0.0;
    }
    json["completeness_reference"] = references.seen->string();
    json["completeness_samples"] = against_seen.reference_samples;
    json["reference_samples"] = against_seen.reference_samples;
    json["samples_per_m2"] = against_seen.samples_per_m2;
  }
  if (against_surface_out) *against_surface_out = std::move(against_surface);
  return json;
}

bool has_surface_reference(const MeshReferences& references) {
  // A reference may be missing: a simulation that was interrupted wrote no ground truth.
  return references.surface && fs::exists(*references.surface);
}

}  // namespace

std::optional<nlohmann::json> evaluate_map_mesh(
    const mesh::TriangleMesh& mesh, const MeshReferences& references,
    const std::optional<Eigen::Isometry3d>& T_truth_estimate,
    const MeshErrorOutputs* error_outputs) {
  if (!has_surface_reference(references) || mesh.triangles.empty()) return std::nullopt;
  mesh::CompareResult against_surface;
  nlohmann::json json =
      evaluate_by_region(mesh::MeshRegions(mesh), references, T_truth_estimate, &against_surface);
  if (error_outputs) {
    json["error_files"] =
        write_mesh_error_files(error_outputs->dir, mesh, against_surface, error_outputs->plan.paths,
                               error_outputs->plan.settings);
  }
  return json;
}

std::optional<nlohmann::json> evaluate_tile_set(
    const fs::path& tile_set_dir, const MeshReferences& references,
    const std::optional<Eigen::Isometry3d>& T_truth_estimate) {
  if (!has_surface_reference(references)) return std::nullopt;
  const std::unique_ptr<mesh::SurfaceRegions> tiles =
      viewer_export::open_tile_set_regions(tile_set_dir);
  if (tiles->bounds().isEmpty()) return std::nullopt;
  return evaluate_by_region(*tiles, references, T_truth_estimate, nullptr);
}

}  // namespace featsense::app
