#include "view_content.hpp"

#include <spdlog/spdlog.h>

#include <fstream>
#include <optional>
#include <vector>

#include "featsense/mesh/navigation_layers.hpp"
#include "featsense/mesh/vertex_clustering.hpp"
#include "featsense/slam/trajectory/trajectory_io.hpp"
#include "featsense/viewer_export/error_colours.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"
#include "featsense/viewer_export/viewer_mesh_binary.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

/// The layer `name` of the PLY `file`, where the file exists and describes the same vertices
/// (a file from another mesh is skipped with a warning rather than shown wrongly).
std::optional<std::vector<float>> vertex_layer(const fs::path& file, const std::string& name,
                                               const mesh::TriangleMesh& mesh) {
  if (!fs::is_regular_file(file)) return std::nullopt;
  try {
    viewer_export::MeshAttributes attributes;
    const mesh::TriangleMesh other = viewer_export::read_mesh(file.string(), &attributes);
    for (viewer_export::VertexScalar& layer : attributes.scalars) {
      if (layer.name != name) continue;
      if (other.vertices.size() == mesh.vertices.size()) return std::move(layer.values);
      spdlog::warn("{}: {} vertices, the mesh has {}: no {} colouring", file.string(),
                   other.vertices.size(), mesh.vertices.size(), name);
      return std::nullopt;
    }
    spdlog::warn("{}: no layer {}", file.string(), name);
  } catch (const std::exception& e) {
    spdlog::warn("{}: not read ({}): no {} colouring", file.string(), e.what(), name);
  }
  return std::nullopt;
}

/// A path of the page: the positions of the trajectory in `file`, where it can be read.
std::optional<nlohmann::json> path_json(const fs::path& file, const std::string& label) {
  if (!fs::is_regular_file(file)) return std::nullopt;
  try {
    const slam::Trajectory trajectory = slam::read_tum(file.string());
    nlohmann::json positions = nlohmann::json::array();
    for (const Eigen::Isometry3d& T_map_sensor : trajectory.poses) {
      const Eigen::Vector3d p = T_map_sensor.translation();
      positions.push_back({p.x(), p.y(), p.z()});
    }
    return nlohmann::json{
        {"label", label}, {"file", file.filename().string()}, {"positions_m", positions}};
  } catch (const std::exception& e) {
    spdlog::warn("{}: not read ({}): the path is not shown", file.string(), e.what());
    return std::nullopt;
  }
}

fs::path find_mesh_file(const fs::path& folder) {
  if (!fs::exists(folder)) throw ViewError("no such folder: " + folder.string());
  if (!fs::is_directory(folder))
    throw ViewError(folder.string() +
                    " is not a folder: give the output folder of featsense map, "
                    "demo or mesh");
  for (const char* name : {"mesh.ply", "mesh.glb"}) {
    if (fs::is_regular_file(folder / name)) return folder / name;
  }
  throw ViewError(folder.string() +
                  " holds no mesh (mesh.ply or mesh.glb): give the output folder of featsense "
                  "map, demo or mesh");
}

}  // namespace

std::optional<std::string> read_file_bytes(const fs::path& file) {
  if (!fs::is_regular_file(file)) return std::nullopt;  // a folder opens, but has no size
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) return std::nullopt;
  std::string bytes(static_cast<size_t>(in.tellg()), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) return std::nullopt;
  return bytes;
}

ViewContent load_view_content(const fs::path& folder, const ViewSettings& settings) {
  const fs::path mesh_file = find_mesh_file(folder);
  mesh::TriangleMesh full;
  try {
    full = viewer_export::read_mesh(mesh_file.string());
  } catch (const std::exception& e) {
    throw ViewError(std::string("cannot read the mesh: ") + e.what());
  }
  if (full.triangles.empty()) throw ViewError(mesh_file.string() + " has no triangles");

  std::vector<viewer_export::VertexScalar> layers;
  if (auto values = vertex_layer(folder / "mesh_error.ply", "signed_distance", full))
    layers.push_back({"signed_distance", std::move(*values)});
  if (auto values = vertex_layer(folder / "navmesh.ply", "cost", full))
    layers.push_back({"cost", std::move(*values)});

  mesh::ClusteredMesh shown = mesh::cluster_vertices(full, settings.max_triangles);
  const bool simplified = shown.cell_size_m > 0.0;
  if (simplified) {
    for (viewer_export::VertexScalar& layer : layers)
      layer.values = mesh::average_per_cluster(shown, layer.values);
    shown.mesh.normals = mesh::vertex_normals(shown.mesh);
  } else {
    shown.mesh.normals = mesh::vertex_normals(full);
  }

  ViewContent content;
  content.mesh_binary = viewer_export::encode_viewer_mesh(shown.mesh, layers);
  Eigen::Vector3f lo;
  Eigen::Vector3f hi;
  shown.mesh.bounds(&lo, &hi);
  nlohmann::json layer_names = nlohmann::json::array();
  for (const viewer_export::VertexScalar& layer : layers) layer_names.push_back(layer.name);
  // The folder's name, also when given as "out/" (whose last component is empty).
  fs::path absolute = fs::absolute(folder).lexically_normal();
  if (absolute.filename().empty()) absolute = absolute.parent_path();
  content.scene["name"] = absolute.filename().string();
  content.scene["mesh"] = {
      {"file", mesh_file.filename().string()},
      {"vertices", shown.mesh.vertices.size()},
      {"triangles", shown.mesh.triangles.size()},
      {"source_triangles", full.triangles.size()},
      {"simplified", simplified},
      {"cell_size_m", shown.cell_size_m},
      {"layers", layer_names},
      {"bytes", content.mesh_binary.size()},
      {"bounds_m", {{"lo", {lo.x(), lo.y(), lo.z()}}, {"hi", {hi.x(), hi.y(), hi.z()}}}}};
  content.scene["error_saturation_m"] = viewer_export::kErrorSaturationM;
  nlohmann::json paths = nlohmann::json::array();
  if (auto path = path_json(folder / "trajectory.tum", "estimate")) paths.push_back(*path);
  for (const fs::path& truth :
       {folder / "ground_truth" / "gt_trajectory.tum", folder / "gt_trajectory.tum"}) {
    if (auto path = path_json(truth, "truth")) {
      paths.push_back(*path);
      break;
    }
  }
  content.scene["paths"] = paths;
  if (auto plan = read_file_bytes(folder / "topdown.png")) content.plan_png = std::move(*plan);
  content.scene["plan"] =
      content.plan_png.empty() ? nlohmann::json(nullptr) : nlohmann::json("topdown.png");
  return content;
}

}  // namespace featsense::app
