#pragma once
// Writing navigation layers (mesh/navigation_layers.hpp) to a mesh file, one mesh or a tile
// set's tiles a few at a time (`featsense navmesh`).

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <string>

#include "featsense/mesh/navigation_layers.hpp"
#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::app {

/// Writes `mesh` with its layers as scalar fields (inclination_deg, roughness_deg,
/// height_diff_m, cost, lethal per vertex), coloured by cost, to `path` (.ply, .glb, .gltf,
/// .obj; .h5 with the lethal faces under face_attributes). Adds normals where the mesh has
/// none. Returns the lethal triangles.
std::size_t write_navigation_mesh(const std::string& path, mesh::TriangleMesh& mesh,
                                  const mesh::NavigationLayers& layers);

/// The layers of a tile set's full-resolution tiles (tile_set.hpp), one file per tile in
/// `out_dir` (X_Y.EXT, EXT from `extension`: ".ply", ".glb", ...) and `navmesh.json` (the
/// tiles, their triangles and lethal ones, the settings). Each tile is computed with the
/// triangles of the tiles around it within the radius, welded by position, so that its
/// border vertices have the neighbourhoods and normals they have in the whole mesh. Those
/// parts are cut from each tile in a first pass and kept in `out_dir`/.margins until used, so
/// every tile is read twice and memory is that of the tiles in work (at most 4 threads).
/// Returns navmesh.json's content.
nlohmann::json write_navigation_tiles(const std::filesystem::path& tile_set_dir,
                                      const std::filesystem::path& out_dir,
                                      const std::string& extension,
                                      const mesh::NavigationSettings& settings, bool quiet);

}  // namespace featsense::app
