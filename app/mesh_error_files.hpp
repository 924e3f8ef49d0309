#pragma once
// The mesh's error made visible: its vertices' distances to the reference as files that
// CloudCompare and any glTF viewer open (`featsense eval mesh --ply-out`, and mesh_error.* of
// `featsense map` and `demo`).

#include <nlohmann/json.hpp>

#include <filesystem>
#include <vector>

#include "featsense/mesh/compare_to_reference.hpp"
#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/viewer_export/plan_view.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::app {

/// The layers `distance` (|d|) and `signed_distance`, per vertex, metres: written to PLY as
/// scalar_distance and scalar_signed_distance, which CloudCompare shows as scalar fields.
viewer_export::MeshAttributes distance_layers(const mesh::CompareResult& result);

/// Writes `out`/mesh_error.ply (the distance layers), `out`/mesh_error.glb (vertex colours by
/// signed distance: blue behind the reference, white on it, red in front, saturated at
/// viewer_export::kErrorSaturationM) and `out`/mesh_error.png (the plan view in those colours,
/// cut as topdown.png is, with `paths`). Returns the report's account of them: the files and
/// the colour map's saturation.
nlohmann::json write_mesh_error_files(const std::filesystem::path& out,
                                      const mesh::TriangleMesh& mesh,
                                      const mesh::CompareResult& result,
                                      const std::vector<viewer_export::PlanPath>& paths,
                                      const viewer_export::PlanViewSettings& plan_settings);

}  // namespace featsense::app
