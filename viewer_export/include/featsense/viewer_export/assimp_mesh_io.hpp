#pragma once
/// Reads any mesh file that assimp imports (glTF/GLB, COLLADA, OBJ, PLY, STL, FBX, ...) into
/// our map frame: metres, Z up. The one reader of foreign mesh formats, for the mesh commands
/// (glTF/GLB through `read_mesh`) and for the simulator's scene files.
///
/// The node tree is walked with its transforms applied in double precision, so that re-centred
/// glTF files come back exact far from the origin; a mesh that several nodes refer to comes
/// once per node.
///
/// Up axis, one rule: assimp's glTF importer hands glTF/GLB over Y up (glTF's own
/// convention), and its COLLADA importer turns a document Y up from its `<up_axis>` (scaling it
/// to metres by its `<unit>`); every other format carries no up axis and is taken as Z up, this
/// project's convention. `up_axis` "auto" applies that rule by the file's extension (`.gltf`,
/// `.glb`, `.dae`: Y up); "y" or "z" states the axis of a file that breaks it (an OBJ exported
/// Y up). Y up becomes Z up by a +90 deg turn about x: (x, y, z) -> (x, -z, y).
///
/// Parts: each of the file's meshes that holds triangles becomes a part named after it, its
/// reflectance the mean of its material's diffuse colour (clamped to 0.02..0.98), else
/// `default_reflectance`.

#include <string>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/viewer_export/mesh_file_error.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::viewer_export {

struct AssimpReadOptions {
  double unit_scale = 1.0;       ///< the file's coordinates times this are metres (> 0)
  std::string up_axis = "auto";  ///< "auto", "y" or "z" (see above)
  float default_reflectance = mesh::MeshPart::kDefaultReflectance;
  /// Surfaces to cast rays against: points and lines are dropped, vertices identical in every
  /// attribute are joined, and a file without triangles is an error. Otherwise the file's
  /// vertices stay as they are, in their order (a point cloud reads as one).
  bool surfaces_only = false;
};

/// The mesh of `path` (see above); per-vertex normals where every mesh has them, colours to
/// `attributes` where given and every mesh has them. Throws MeshFileError naming the file when
/// it is missing or unreadable, an option is invalid or a coordinate is not finite.
mesh::TriangleMesh read_mesh_with_assimp(const std::string& path,
                                         MeshAttributes* attributes = nullptr,
                                         const AssimpReadOptions& options = {});

}  // namespace featsense::viewer_export
