// featsense mesh MAP -o MESH [--plan PNG] [--tiles DIR]: marching cubes over a stored map (.h5
// or .vdb), one welded mesh and its plan view, or a tile set (a mesh per tile and a 3D Tiles
// tileset) whose memory is bounded by the tile, not the map.

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/mesh/mesh_cleanup.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/storage/memory_chunk_store.hpp"
#include "featsense/storage/vdb_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"
#include "json_output.hpp"
#include "map_outputs.hpp"
#include "mesh_tile_set.hpp"

namespace featsense::app {
namespace {

struct MeshOptions {
  std::string map;
  std::string output;
  std::string bbox;
  double min_weight = mesh::MeshingSettings{}.min_weight;
  int threads = 0;
  std::size_t cache_mb = 64;
  bool clean = false;
  double simplify_ratio = 1.0;
  double min_component_area_m2 = 0.25;
  double max_hole_perimeter_m = 1.0;
  bool check_self_intersections = false;
  std::optional<std::string> json_path;
  std::optional<std::string> plan_path;        ///< the plan view, PNG
  std::optional<double> plan_height;           ///< its cut
  std::optional<std::string> trajectory_path;  ///< the path drawn on it (and its cut)
  std::optional<std::string> tiles_dir;        ///< the tile set's folder
  double tile_size_m = viewer_export::TileSetSettings{}.tile_size_m;
  std::size_t tiles_in_work = viewer_export::TileSetSettings{}.tiles_in_work;
  bool tile_ply = true;
  bool quiet = false;
};

/// --plan's options make sense only with it, and the file must be a PNG.
void check_plan_options(const MeshOptions& options) {
  if (!options.plan_path) {
    if (options.plan_height) throw config::ConfigError("--plan-height goes with --plan FILE.png");
    if (options.trajectory_path)
      throw config::ConfigError("--trajectory goes with --plan FILE.png");
    return;
  }
  if (viewer_export::mesh_extension(*options.plan_path) != ".png") {
    throw config::ConfigError("--plan: the plan view is a PNG file, got '" + *options.plan_path +
                              "'");
  }
}

/// The --trajectory's path, read before the meshing so that a bad file fails at once.
std::vector<viewer_export::PlanPath> plan_paths(const MeshOptions& options) {
  if (!options.trajectory_path) return {};
  return {plan_path(slam::read_trajectory(*options.trajectory_path),
                    viewer_export::PlanPath::Kind::kEstimate, "path")};
}

/// "xmin,ymin,zmin,xmax,ymax,zmax" in metres.
Eigen::AlignedBox3d parse_bbox(const std::string& text) {
  std::istringstream in(text);
  std::array<double, 6> v{};
  for (size_t i = 0; i < v.size(); ++i) {
    char comma = ',';
    if (i > 0) in >> comma;
    if (!(in >> v[i]) || comma != ',' || !std::isfinite(v[i])) {
      throw config::ConfigError("--bbox: expected xmin,ymin,zmin,xmax,ymax,zmax in metres, got '" +
                                text + "'");
    }
  }
  in >> std::ws;
  if (!in.eof()) {
    throw config::ConfigError("--bbox: expected six numbers, got '" + text + "'");
  }
  const Eigen::Vector3d lo(v[0], v[1], v[2]);
  const Eigen::Vector3d hi(v[3], v[4], v[5]);
  if ((lo.array() >= hi.array()).any()) {
    throw config::ConfigError("--bbox: each minimum must be below its maximum, got '" + text + "'");
  }
  return {lo, hi};
}

bool starts_with_bytes(const std::string& path, const std::string& magic) {
  std::ifstream in(path, std::ios::binary);
  std::string head(magic.size(), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  return in.gcount() == static_cast<std::streamsize>(magic.size()) && head == magic;
}

/// The map as a chunk store: an HDF5 map read in place (cache bounded), a .vdb imported into
/// memory.
std::unique_ptr<storage::ChunkStore> open_map(const MeshOptions& options) {
  const std::filesystem::path path(options.map);
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error(options.map + ": no such map file");
  }
  const std::string extension = viewer_export::mesh_extension(options.map);
  if (extension == ".vdb") {
    auto store = std::make_unique<storage::MemoryChunkStore>(storage::read_vdb_metadata(path));
    storage::import_vdb(path, *store);
    return store;
  }
  if (extension == ".h5" || starts_with_bytes(options.map, "\x89HDF")) {
    storage::StoreSettings settings;
    settings.cache_bytes = options.cache_mb << 20;
    return std::make_unique<storage::Hdf5ChunkStore>(path, settings);
  }
  throw std::runtime_error(options.map + ": not a featsense map (expected .h5 or .vdb)");
}

/// --tiles works tile by tile; what needs the whole mesh at once needs -o.
void check_tile_options(const MeshOptions& options) {
  if (!options.tiles_dir) return;
  if (!(options.tile_size_m > 0.0) || !std::isfinite(options.tile_size_m)) {
    throw config::ConfigError("--tile-size: must be a positive number of metres, got " +
                              std::to_string(options.tile_size_m));
  }
  if (options.output.empty() &&
      (options.simplify_ratio < 1.0 || options.check_self_intersections || options.plan_path)) {
    throw config::ConfigError(
        "--simplify, --check-self-intersections and --plan work on one mesh: give -o FILE with "
        "--tiles (the tile set has its own coarser levels; --clean cleans each tile)");
  }
}

/// Bad option values fail before the map is read.
void check_options(const MeshOptions& options) {
  if (options.output.empty() && !options.tiles_dir) {
    throw config::ConfigError("give -o MESH (one mesh), --tiles DIR (a tile set), or both");
  }
  check_tile_options(options);
  const std::string extension = viewer_export::mesh_extension(options.output);
  if (!options.output.empty() && extension != ".ply" && extension != ".glb" &&
      extension != ".gltf" && extension != ".obj") {
    throw config::ConfigError("-o: unknown mesh format '" + extension +
                              "' (use .ply, .glb, .gltf or .obj)");
  }
  if (!(options.min_weight >= 0.0) || !std::isfinite(options.min_weight)) {
    throw config::ConfigError("--min-weight: must be a number of measurements >= 0, got " +
                              std::to_string(options.min_weight));
  }
  if (options.threads < 0) {
    throw config::ConfigError("--threads: must be >= 0 (0 = all cores), got " +
                              std::to_string(options.threads));
  }
  if (!(options.simplify_ratio > 0.0 && options.simplify_ratio <= 1.0)) {
    throw config::ConfigError(
        "--simplify: the fraction of triangles to keep must be in (0, 1], got " +
        std::to_string(options.simplify_ratio));
  }
  if (!(options.min_component_area_m2 >= 0.0) || !(options.max_hole_perimeter_m >= 0.0)) {
    throw config::ConfigError("--min-component-area and --max-hole must be >= 0");
  }
  check_plan_options(options);
}

/// What a mesh run made, for the summary and --json.
struct MeshRun {
  mesh::MeshingSettings settings;
  mesh::MeshingStats stats;
  mesh::TriangleMesh result;
  std::optional<mesh::CleanupReport> cleanup;
  std::optional<viewer_export::PlanView> plan;

  double triangles_per_s() const {
    return stats.seconds > 0.0 ? static_cast<double>(stats.triangles) / stats.seconds : 0.0;
  }
};

void print_summary(const MeshOptions& options, const MeshRun& run) {
  std::printf(
      "%s: %zu vertices, %zu triangles (meshed: %zu) from %zu chunks in %.2f s (%.2f M "
      "triangles/s)\n",
      options.output.c_str(), run.result.vertices.size(), run.result.triangles.size(),
      run.stats.triangles, run.stats.chunks, run.stats.seconds, run.triangles_per_s() * 1e-6);
  if (run.cleanup) {
    const mesh::CleanupReport& c = *run.cleanup;
    std::printf(
        "cleanup: %zu -> %zu triangles, %zu small components removed, %zu non-manifold vertices "
        "split, %zu holes filled, simplification error max %.4f m mean %.4f m, %s, %s\n",
        c.input_triangles, c.output_triangles, c.removed_components, c.non_manifold_vertices_fixed,
        c.holes_filled, c.simplification_max_error_m, c.simplification_mean_error_m,
        c.is_closed ? "closed" : "open", c.is_manifold ? "manifold" : "not manifold");
  }
  if (run.plan) {
    std::printf("plan view: %s, %d x %d pixels of %.3f m, grid %g m; cut: %s\n",
                options.plan_path->c_str(), run.plan->width_px, run.plan->height_px,
                run.plan->pixel_size_m, run.plan->grid_spacing_m, run.plan->cut_rule.c_str());
  }
}

nlohmann::json cleanup_json(const mesh::CleanupReport& c, const MeshOptions& options) {
  nlohmann::json out = {{"input_triangles", c.input_triangles},
                        {"output_triangles", c.output_triangles},
                        {"output_vertices", c.output_vertices},
                        {"degenerate_triangles_removed", c.degenerate_triangles_removed},
                        {"removed_components", c.removed_components},
                        {"removed_component_triangles", c.removed_component_triangles},
                        {"non_manifold_vertices_fixed", c.non_manifold_vertices_fixed},
                        {"holes_filled", c.holes_filled},
                        {"holes_left", c.holes_left},
                        {"simplify_ratio", options.simplify_ratio},
                        {"simplification_max_error_m", c.simplification_max_error_m},
                        {"simplification_mean_error_m", c.simplification_mean_error_m},
                        {"border_edges", c.border_edges},
                        {"is_closed", c.is_closed},
                        {"is_manifold", c.is_manifold},
                        {"is_valid", c.is_valid},
                        {"seconds", c.seconds}};
  if (options.check_self_intersections) out["self_intersections"] = c.self_intersections;
  return out;
}

nlohmann::json mesh_run_json(const MeshOptions& options, const MeshRun& run) {
  nlohmann::json report = {{"map", options.map},
                           {"output", options.output},
                           {"vertices", run.result.vertices.size()},
                           {"triangles", run.result.triangles.size()},
                           {"chunks", run.stats.chunks},
                           {"voxels", run.stats.voxels},
                           {"seconds", run.stats.seconds},
                           {"triangles_per_s", run.triangles_per_s()},
                           {"min_weight", options.min_weight}};
  if (run.settings.bbox) {
    const Eigen::AlignedBox3d& box = *run.settings.bbox;
    report["bbox"] = {box.min().x(), box.min().y(), box.min().z(),
                      box.max().x(), box.max().y(), box.max().z()};
  }
  if (run.cleanup) report["cleanup"] = cleanup_json(*run.cleanup, options);
  if (run.plan) report["plan"] = plan_json(*run.plan, *options.plan_path);
  return report;
}

void run_mesh(const MeshOptions& options) {
  check_options(options);
  const std::vector<viewer_export::PlanPath> paths = plan_paths(options);
  MeshRun run;
  run.settings.min_weight = options.min_weight;
  run.settings.threads = options.threads;
  if (!options.bbox.empty()) run.settings.bbox = parse_bbox(options.bbox);

  std::unique_ptr<storage::ChunkStore> store = open_map(options);
  std::optional<nlohmann::json> tiles;
  if (options.tiles_dir) {
    viewer_export::TileSetSettings tiling;
    tiling.tile_size_m = options.tile_size_m;
    tiling.meshing = run.settings;
    tiling.write_ply = options.tile_ply;
    tiling.tiles_in_work = options.tiles_in_work;
    if (options.clean) {
      mesh::CleanupSettings cleaning;
      cleaning.min_component_area_m2 = options.min_component_area_m2;
      cleaning.max_hole_perimeter_m = options.max_hole_perimeter_m;
      cleaning.check_self_intersections = false;
      tiling.cleanup = cleaning;
    }
    tiles = write_tile_set_with_progress(*store, *options.tiles_dir, tiling, options.quiet);
    if (options.output.empty()) {
      if (options.json_path)
        write_json({{"map", options.map}, {"tiles", *tiles}}, *options.json_path);
      return;
    }
  }
  run.result = mesh::extract_mesh(*store, run.settings, &run.stats);
  store.reset();
  if (run.result.triangles.empty()) {
    throw std::runtime_error(options.map + ": no surface to mesh" +
                             (run.settings.bbox ? " inside --bbox" : "") + " (" +
                             std::to_string(run.stats.chunks) + " chunks, min weight " +
                             std::to_string(options.min_weight) + ")");
  }
  if (options.clean || options.simplify_ratio < 1.0 || options.check_self_intersections) {
    mesh::CleanupSettings cleaning;
    if (options.clean) {
      cleaning.min_component_area_m2 = options.min_component_area_m2;
      cleaning.max_hole_perimeter_m = options.max_hole_perimeter_m;
    }
    cleaning.simplify_ratio = options.simplify_ratio;
    cleaning.check_self_intersections = options.check_self_intersections;
    run.cleanup = mesh::clean_mesh(run.result, cleaning);
    if (run.result.triangles.empty()) {
      throw std::runtime_error(options.map + ": nothing left after cleaning (" +
                               std::to_string(run.cleanup->removed_components) +
                               " small components removed)");
    }
  }
  viewer_export::write_mesh(options.output, run.result);
  if (options.plan_path) {
    // The path, where given, sets the cut; --plan-height overrides it.
    viewer_export::PlanViewSettings plan_settings;
    plan_settings.cut_height_m = options.plan_height;
    run.plan =
        viewer_export::write_plan_view_png(run.result, paths, *options.plan_path, plan_settings);
  }
  print_summary(options, run);
  if (options.json_path) {
    nlohmann::json report = mesh_run_json(options, run);
    if (tiles) report["tiles"] = *tiles;
    write_json(report, *options.json_path);
  }
}

}  // namespace

Command register_mesh(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<MeshOptions>();
  CLI::App* command = app.add_subcommand(
      "mesh", "Marching cubes over a map (.h5 store or .vdb): one welded mesh with normals");
  command->add_option("MAP", options->map, "The map: map.h5 (featsense map) or a .vdb export")
      ->required();
  command->add_option("-o,--output", options->output,
                      "Output mesh: .ply .glb .gltf .obj (one mesh of the whole map)");
  command->add_option("--tiles", options->tiles_dir,
                      "Write a tile set here: a mesh per tile (GLB, PLY), tiles.json, and a 3D "
                      "Tiles 1.1 tileset.json with coarser levels; memory bounded by the tile");
  command
      ->add_option("--tile-size", options->tile_size_m,
                   "With --tiles: edge of a tile, metres (rounded to whole chunks)")
      ->capture_default_str();
  command->add_flag("!--no-tile-ply", options->tile_ply, "With --tiles: GLB only, no PLY per tile");
  command
      ->add_option("--tiles-in-work", options->tiles_in_work,
                   "With --tiles: tiles cleaned and written at once, each up to about 1 GB for "
                   "a dense 50 m tile (the marching cubes use --threads)")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  command->add_option("--bbox", options->bbox,
                      "Only this box: xmin,ymin,zmin,xmax,ymax,zmax (metres, map frame)");
  command
      ->add_option("--min-weight", options->min_weight,
                   "Measurements each voxel of a cube needs for it to get faces")
      ->capture_default_str();
  command->add_option("--threads", options->threads, "Worker threads, 0 = all cores")
      ->capture_default_str();
  command->add_option("--cache-mb", options->cache_mb, "Chunk cache of an .h5 map, MiB")
      ->check(CLI::Range(1, 1 << 20))
      ->capture_default_str();
  command->add_flag("--clean", options->clean,
                    "Remove small components (--min-component-area), split non-manifold "
                    "vertices, fill holes (--max-hole); with --tiles each tile, its cuts held");
  command
      ->add_option("--min-component-area", options->min_component_area_m2,
                   "With --clean: smaller components are removed, square metres")
      ->capture_default_str();
  command
      ->add_option("--max-hole", options->max_hole_perimeter_m,
                   "With --clean: holes with a shorter border are filled, metres (0 = none)")
      ->capture_default_str();
  command
      ->add_option("--simplify", options->simplify_ratio,
                   "Keep this fraction of the triangles (0, 1] by edge collapse; borders stay")
      ->capture_default_str();
  command->add_flag("--check-self-intersections", options->check_self_intersections,
                    "Count self-intersecting triangle pairs of the result (slow on big meshes)");
  command->add_option("--json", options->json_path, "Write the figures as JSON ('-' = stdout)");
  command->add_option("--plan", options->plan_path,
                      "Also write the plan view: the mesh seen from above below a cut height, "
                      "with a grid and a scale bar (PNG)");
  add_plan_height_option(*command, options->plan_height);
  command
      ->add_option("--trajectory", options->trajectory_path,
                   "With --plan: the sensor's path (TUM or KITTI) to draw and to cut above")
      ->check(CLI::ExistingFile);
  return {command, [options, &context] {
            options->quiet = context.quiet;
            run_mesh(*options);
          }};
}

}  // namespace featsense::app
