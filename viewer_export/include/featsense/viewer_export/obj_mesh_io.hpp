#pragma once
/// Wavefront OBJ meshes.
///
/// Writing: `v x y z [r g b]` (colours as the common vertex-colour extension, 0..1, which
/// MeshLab, CloudCompare and Blender read), `vn` per vertex where the mesh has normals, and
/// faces `f a//a ...`. Where colours are present an MTL file beside the OBJ (same stem,
/// `.mtl`) holds a white material whose diffuse colour the vertex colours modulate. OBJ has no
/// place for scalar layers: they are not written. Coordinates are written with 9 significant
/// digits, so float vertices read back bit for bit.
/// Reading: `v` (with or without colour), `vn`, `f` in any of its index forms (negative
/// indices too); polygons are split into a fan of triangles; other statements are skipped.

#include <string>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/viewer_export/mesh_file_error.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::viewer_export {

/// Writes the OBJ (and its MTL where colours are present); throws MeshFileError naming the
/// file when a layer does not match the vertices or a file cannot be written.
void write_obj_mesh(const std::string& path, const mesh::TriangleMesh& mesh,
                    const MeshAttributes& attributes = {});

/// Reads an OBJ mesh; vertex colours, where present, go to `colors` (may be null). Normals are
/// kept where every vertex gets one from the faces. Throws MeshFileError naming the file.
mesh::TriangleMesh read_obj_mesh(const std::string& path, MeshAttributes* colors = nullptr);

}  // namespace featsense::viewer_export
