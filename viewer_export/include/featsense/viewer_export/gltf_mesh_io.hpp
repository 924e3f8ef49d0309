#pragma once
/// glTF 2.0 meshes, binary (`.glb`) or JSON with a `.bin` beside it (`.gltf`).
///
/// Written by our own code (JSON through nlohmann_json plus one binary buffer) so that the
/// origin node, its extras and the accessor bounds are exactly as the Khronos validator wants.
/// Frames: our map frame is Z up, glTF is Y up: (x, y, z)_gltf = (x, z, -y)_map, metres.
/// Float32 positions lose millimetres far from the origin, so positions are stored relative
/// to an origin (the bounding-box centre rounded to whole metres, exact in float32), which is
/// the translation of the parent node `map_origin`; its extras say the offset in the map frame
/// (`featsense_origin_map_m`). Per vertex: POSITION, NORMAL (given or area-weighted), COLOR_0
/// (RGBA bytes) where colours are present, and each scalar layer as an application-specific
/// float attribute `_<NAME>` (upper case). A mesh without triangles is written as points.
/// Reading them back: `read_mesh_with_assimp` (assimp_mesh_io.hpp).

#include <string>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/viewer_export/mesh_file_error.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::viewer_export {

/// Writes `.glb` (one file) or `.gltf` (+ `<stem>.bin`), chosen by `binary`; throws
/// MeshFileError naming the file.
void write_gltf_mesh(const std::string& path, const mesh::TriangleMesh& mesh,
                     const MeshAttributes& attributes, bool binary);

}  // namespace featsense::viewer_export
