// Reads meshes through assimp, walking the node tree with transforms in double precision so
// that re-centred glTF files come back exact far from the origin.

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <assimp/Importer.hpp>
#include <cmath>

#include "featsense/viewer_export/gltf_mesh_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::viewer_export {
namespace {

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3,
      m.d4;
  return out;
}

uint8_t to_byte(float value) {
  return static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 255.0f));
}

struct Collector {
  const aiScene* scene;
  bool from_y_up;
  mesh::TriangleMesh mesh;
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> colors;
  bool all_colors = true;
  bool all_normals = true;

  Eigen::Vector3d to_map(const Eigen::Vector3d& p) const {
    return from_y_up ? Eigen::Vector3d(p.x(), -p.z(), p.y()) : p;
  }

  void visit(const aiNode* node, const Eigen::Matrix4d& parent) {
    const Eigen::Matrix4d T = parent * to_eigen(node->mTransformation);
    const Eigen::Matrix3d R_normal = T.topLeftCorner<3, 3>().inverse().transpose();
    for (unsigned m = 0; m < node->mNumMeshes; ++m) {
      const aiMesh* part = scene->mMeshes[node->mMeshes[m]];
      const int base = static_cast<int>(mesh.vertices.size());
      for (unsigned i = 0; i < part->mNumVertices; ++i) {
        const aiVector3D& v = part->mVertices[i];
        const Eigen::Vector3d p = (T * Eigen::Vector4d(v.x, v.y, v.z, 1.0)).head<3>();
        mesh.vertices.push_back(to_map(p).cast<float>());
        if (part->HasNormals()) {
          const aiVector3D& nv = part->mNormals[i];
          mesh.normals.push_back(
              to_map((R_normal * Eigen::Vector3d(nv.x, nv.y, nv.z)).normalized()).cast<float>());
        }
        if (part->HasVertexColors(0)) {
          const aiColor4D& c = part->mColors[0][i];
          colors.emplace_back(to_byte(c.r), to_byte(c.g), to_byte(c.b));
        }
      }
      all_normals = all_normals && part->HasNormals();
      all_colors = all_colors && part->HasVertexColors(0);
      for (unsigned f = 0; f < part->mNumFaces; ++f) {
        const aiFace& face = part->mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines of a triangulated import
        mesh.triangles.emplace_back(base + static_cast<int>(face.mIndices[0]),
                                    base + static_cast<int>(face.mIndices[1]),
                                    base + static_cast<int>(face.mIndices[2]));
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) visit(node->mChildren[c], T);
  }
};

}  // namespace

mesh::TriangleMesh read_mesh_with_assimp(const std::string& path, MeshAttributes* attributes) {
  Assimp::Importer importer;
  // No vertex joining: the vertex order stays that of the file.
  const aiScene* scene = importer.ReadFile(path, aiProcess_Triangulate);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw MeshFileError(path + ": cannot read: " + importer.GetErrorString());
  }
  const std::string extension = mesh_extension(path);
  Collector collector{scene, extension == ".glb" || extension == ".gltf", {}, {}, true, true};
  collector.visit(scene->mRootNode, Eigen::Matrix4d::Identity());
  if (!collector.all_normals) collector.mesh.normals.clear();
  if (attributes != nullptr && collector.all_colors) attributes->colors = collector.colors;
  return collector.mesh;
}

}  // namespace featsense::viewer_export
