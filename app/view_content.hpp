#pragma once
// What `featsense view` serves from an output folder: the mesh as the page's binary (with its
// error and navigation cost layers where the folder holds them), the paths and the plan view.

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace featsense::app {

/// A folder that cannot be viewed; the message says why and what to do.
class ViewError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ViewSettings {
  /// Above this many triangles the page gets a coarser mesh (vertex clustering): a software
  /// renderer or a small GPU draws 2 M triangles smoothly, and the binary stays under 100 MB.
  std::size_t max_triangles = 2'000'000;
};

struct ViewContent {
  std::string mesh_binary;  ///< viewer_export/viewer_mesh_binary.hpp
  /// What the page needs to know besides: the mesh's counts, bounds and layers, the paths,
  /// whether there is a plan view.
  nlohmann::json scene;
  std::string plan_png;  ///< topdown.png's bytes, empty where there is none
};

/// Reads `folder` (the output of `featsense map`, `demo` or `mesh`): mesh.ply (or mesh.glb);
/// the layer `signed_distance` from mesh_error.ply and `cost` from navmesh.ply where they hold
/// the same vertices; the paths trajectory.tum (the estimate) and the truth,
/// ground_truth/gt_trajectory.tum or gt_trajectory.tum; topdown.png. Throws ViewError for a
/// missing folder or one without a mesh.
ViewContent load_view_content(const std::filesystem::path& folder,
                              const ViewSettings& settings = {});

/// The bytes of `file`, or nullopt where it cannot be read.
std::optional<std::string> read_file_bytes(const std::filesystem::path& file);

}  // namespace featsense::app
