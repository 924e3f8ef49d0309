#pragma once
// What `featsense map` makes of a finished map: the mesh (mesh.ply, mesh.glb), its plan view
// (topdown.png) and, where a reference is known, its evaluation.

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>

#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/slam/trajectory/trajectory.hpp"
#include "featsense/viewer_export/plan_view.hpp"

namespace featsense::app {

struct MapMesh {
  /// The whole map's mesh; with tiles, the tile set's overview (a coarser level, or none).
  mesh::TriangleMesh mesh;
  mesh::MeshingStats stats;
  std::optional<viewer_export::PlanView> plan;  ///< what topdown.png shows
  double write_s = 0.0;
  std::optional<nlohmann::json> tiles;  ///< the tile set's figures (mesh_tile_set.hpp)
  int overview_level = -1;              ///< the tile set's level that `mesh` is
};

/// What the plan view draws besides the mesh: the paths in the map frame, and its settings
/// (--plan-height).
struct PlanInputs {
  std::vector<viewer_export::PlanPath> paths;
  viewer_export::PlanViewSettings settings;
};

/// --plan-height Z: topdown.png's cut, for map, demo and mesh.
void add_plan_height_option(CLI::App& command, std::optional<double>& height_m);

/// A trajectory's positions as a path of the plan view.
viewer_export::PlanPath plan_path(const slam::Trajectory& trajectory,
                                  viewer_export::PlanPath::Kind kind, const std::string& label);

/// Meshes the map at `map_path` and writes `out`/mesh.ply, mesh.glb and topdown.png (the plan
/// view: the map cut below its ceilings, seen from above, with `plan`'s paths).
MapMesh mesh_map(const std::filesystem::path& map_path, const std::filesystem::path& out,
                 const PlanInputs& plan);
/// The map as a tile set in `out`/tiles (viewer_export/tile_set.hpp), memory bounded by a
/// tile; topdown.png from the finest level of at most kOverviewTriangles.
MapMesh mesh_map_tiles(const std::filesystem::path& map_path, const std::filesystem::path& out,
                       const PlanInputs& plan, bool quiet);
inline constexpr std::size_t kOverviewTriangles = 4'000'000;
nlohmann::json mesh_json(const MapMesh& result);

/// The report's account of a plan view written to `file`: its size, its pixels and grid, and
/// where it was cut (null where nothing was).
nlohmann::json plan_json(const viewer_export::PlanView& plan, const std::string& file);

/// Where the truth of a map's surface is: accuracy is measured against `surface` (a mesh),
/// completeness against `seen` (points of the surface the sensor saw, e.g. the simulator's
/// gt_points.ply), or against `surface` itself when there are none.
struct MeshReferences {
  std::optional<std::filesystem::path> surface;
  std::optional<std::filesystem::path> seen;
};

/// Where evaluate_map_mesh shows the mesh's error: the folder, and the plan view's paths and
/// cut, so that mesh_error.png is cut as topdown.png is.
struct MeshErrorOutputs {
  std::filesystem::path dir;
  PlanInputs plan;
};

/// The folder of a simulation's ground truth (gt_trajectory.tum, gt_mesh.ply) for an input:
/// the input itself, a simulated folder; or the folder of a simulated pcap (`simulate --format
/// ouster-pcap|velodyne-pcap` writes recording.pcap beside its truth). Nullopt otherwise.
std::optional<std::filesystem::path> simulation_truth_folder(const std::string& input);

/// The user's reference mesh when given; else the ground truth of a simulation
/// (simulation_truth_folder: gt_mesh.ply, and gt_points.ply where there is one); else none.
MeshReferences find_mesh_references(const std::string& input,
                                    const std::optional<std::string>& user_reference);

/// The `eval.mesh` section of the report (eval_json.hpp keys; completeness and F-score
/// against `seen` where there is one), or nullopt without references. With
/// `T_truth_estimate` (the estimated trajectory's alignment to the true one) also the
/// accuracy of the mesh so aligned, as `aligned`: a map made without an absolute reference
/// (no gravity, no survey points) keeps its first pose's frame, and a tilt of 0.05 deg in
/// its first metres puts a wall 200 m away 17 cm too high however consistent the map is.
/// With `error_outputs`, the distances to `surface` (in the map's frame, as the plain score)
/// are written as mesh_error.ply, .glb and .png (mesh_error_files.hpp), named in `error_files`.
/// The comparison runs a region at a time (mesh/region_comparison.hpp): the truth is read
/// around one region, then the next (the simulator's gt_points.ply a tile at a time), so that
/// the memory is the mesh's and a region's, not the truth's.
std::optional<nlohmann::json> evaluate_map_mesh(
    const mesh::TriangleMesh& mesh, const MeshReferences& references,
    const std::optional<Eigen::Isometry3d>& T_truth_estimate = std::nullopt,
    const MeshErrorOutputs* error_outputs = nullptr);

/// The same for a tile set on disk (`map --tiles`; tile_set.hpp), read a few tiles at a time:
/// the memory of a region, whatever the map's size. No error files (they colour one mesh).
std::optional<nlohmann::json> evaluate_tile_set(
    const std::filesystem::path& tile_set_dir, const MeshReferences& references,
    const std::optional<Eigen::Isometry3d>& T_truth_estimate = std::nullopt);

}  // namespace featsense::app
