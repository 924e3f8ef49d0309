#pragma once
/// PLY meshes and point clouds (ascii, binary little- and big-endian).
///
/// Reading: the `vertex` element's x, y, z (and nx, ny, nz, red, green, blue, scalar_<name>
/// where present) of any numeric type,
/// and the `face` element's index list (`vertex_indices` or `vertex_index`, any count and index
/// type; polygons are split into a fan of triangles). Other elements and properties are
/// skipped. A file without faces reads as a point cloud (a mesh without triangles).
/// Writing: binary little-endian by default, float x y z, optional normals, per-vertex colour
/// and per-vertex float layers written as `scalar_<name>` (which CloudCompare shows as scalar
/// fields), then the faces as uchar count + int indices.

#include <Eigen/Core>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::viewer_export {

/// A file that cannot be read or written; the message names the file.
class PlyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A per-vertex float layer, written as property `scalar_<name>`.
struct VertexScalar {
  std::string name;
  std::vector<float> values;  ///< one per vertex
};

/// What to write besides the geometry. Layers and colours are per vertex; later formats
/// (glTF, OBJ) take the same description.
struct MeshAttributes {
  std::vector<VertexScalar> scalars;
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> colors;  ///< per vertex RGB, or empty
};

/// Reads a PLY mesh or point cloud; throws PlyError naming the file and what is wrong. Where
/// `attributes` is given, it receives the vertex colours (red, green, blue) and every
/// `scalar_<name>` vertex property as layer `<name>`.
mesh::TriangleMesh read_ply_mesh(const std::string& path, MeshAttributes* attributes = nullptr);

struct PlyWriteSettings {
  bool binary = true;  ///< binary little-endian; false: ascii
};

/// Writes the mesh (a point cloud where it has no triangles); throws PlyError when a layer's
/// length differs from the vertex count or the file cannot be written.
void write_ply_mesh(const std::string& path, const mesh::TriangleMesh& mesh,
                    const MeshAttributes& attributes = {}, const PlyWriteSettings& settings = {});

}  // namespace featsense::viewer_export
