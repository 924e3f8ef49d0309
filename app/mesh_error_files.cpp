#include "mesh_error_files.hpp"

#include <cmath>

#include "featsense/viewer_export/error_colours.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::app {

viewer_export::MeshAttributes distance_layers(const mesh::CompareResult& result) {
  viewer_export::MeshAttributes attributes;
  attributes.scalars.push_back({"distance", result.unsigned_distance_m});
  attributes.scalars.push_back({"signed_distance", result.signed_distance_m});
  return attributes;
}

nlohmann::json write_mesh_error_files(const std::filesystem::path& out,
                                      const mesh::TriangleMesh& mesh,
                                      const mesh::CompareResult& result,
                                      const std::vector<viewer_export::PlanPath>& paths,
                                      const viewer_export::PlanViewSettings& plan_settings) {
  viewer_export::write_mesh((out / "mesh_error.ply").string(), mesh, distance_layers(result));
  // Colours only: a glTF viewer shows them, and the PLY beside it holds the values.
  viewer_export::MeshAttributes coloured;
  coloured.colors = viewer_export::signed_distance_colours(result.signed_distance_m);
  viewer_export::write_mesh((out / "mesh_error.glb").string(), mesh, coloured);
  const viewer_export::PlanVertexColours plan_colours =
      viewer_export::signed_distance_plan_colours(result.signed_distance_m);
  viewer_export::write_plan_view_png(mesh, paths, (out / "mesh_error.png").string(), plan_settings,
                                     &plan_colours);
  return {
      {"ply", "mesh_error.ply"},
      {"glb", "mesh_error.glb"},
      {"png", "mesh_error.png"},
      // The float constant as the decimal it was written as, not 0.10000000149.
      {"colour_saturation_m", std::round(1e6 * double{viewer_export::kErrorSaturationM}) / 1e6}};
}

}  // namespace featsense::app
