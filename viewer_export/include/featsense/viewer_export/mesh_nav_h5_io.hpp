#pragma once
/// The HDF5 mesh layout that the ROS mesh navigation stack loads (lvr2's MeshIO).
///
/// Written layout (the `geometry/` one of current lvr2 MeshIO; older files used `channels/`):
///   /<part>                              group, attributes IO="MeshIO", CLASS="MeshBuffer"
///   /<part>/geometry/vertices            N x 3 float32, map frame, metres
///   /<part>/geometry/face_indices        M x 3 uint32
///   /<part>/vertex_attributes/vertex_normals   N x 3 float32, unit length
///   /<part>/vertex_attributes/<layer>    N x 1 float32, one per scalar layer
///   /<part>/face_attributes/<layer>      M x 1 float32, one per face layer
/// The part name is "mesh" unless given.

#include <string>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"
#include "featsense/viewer_export/mesh_file_error.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::viewer_export {

/// A per-face float layer (e.g. lethal faces as 0/1).
struct FaceScalar {
  std::string name;
  std::vector<float> values;  ///< one per triangle
};

/// Writes (replacing) the file; throws MeshFileError naming the path.
void write_mesh_nav_h5(const std::string& path, const mesh::TriangleMesh& mesh,
                       const MeshAttributes& attributes,
                       const std::vector<FaceScalar>& face_scalars = {},
                       const std::string& part = "mesh");

}  // namespace featsense::viewer_export
