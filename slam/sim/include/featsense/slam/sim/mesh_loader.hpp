#pragma once
/// Reads scene meshes from files (PLY, OBJ, glTF/GLB, COLLADA, STL, ...) through assimp.

#include <string>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::slam {

struct MeshLoadOptions {
  double unit_scale = 1.0;  ///< multiplies the file's coordinates to get metres
  /// The file's up axis: "z", "y", or "auto" (y for glTF/GLB and COLLADA, whose importer
  /// hands them over Y up after applying the file's own up axis and unit; z otherwise).
  std::string up_axis = "auto";
  float default_reflectance = 0.5f;  ///< for parts whose material has no diffuse colour
};

/// The mesh of `path` in metres, Z up. Each of the file's meshes becomes a part whose
/// reflectance is the mean of its material's diffuse colour (else the default).
/// Throws InputError naming the file when it is missing, unreadable or holds no triangle.
mesh::TriangleMesh load_mesh(const std::string& path, const MeshLoadOptions& options = {});

}  // namespace featsense::slam
