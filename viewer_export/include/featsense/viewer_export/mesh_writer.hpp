#pragma once
/// One entry point for every mesh file format, chosen by the file's extension.

#include <string>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/viewer_export/mesh_file_error.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::viewer_export {

struct MeshWriteSettings {
  bool ply_ascii = false;  ///< PLY as ascii instead of binary little-endian
};

/// Writes `.ply`, `.obj` (+ `.mtl`), `.glb`, `.gltf` (+ `.bin`) or `.h5` (the mesh navigation
/// layout). Throws MeshFileError naming the path for an unknown extension, an empty mesh,
/// non-finite coordinates, layers that do not match the vertices or a file that cannot be
/// written.
void write_mesh(const std::string& path, const mesh::TriangleMesh& mesh,
                const MeshAttributes& attributes = {}, const MeshWriteSettings& settings = {});

/// Reads `.ply`, `.obj`, `.glb` or `.gltf` (the glTF ones back into our Z-up map frame);
/// colours go to `attributes` where given. Throws MeshFileError (PlyError for PLY) naming the
/// path.
mesh::TriangleMesh read_mesh(const std::string& path, MeshAttributes* attributes = nullptr);

/// The lower-case extension with its dot (".ply"), or "" where there is none.
std::string mesh_extension(const std::string& path);

/// Whether `path`'s extension is one write_mesh writes.
bool is_writable_mesh_path(const std::string& path);

}  // namespace featsense::viewer_export
