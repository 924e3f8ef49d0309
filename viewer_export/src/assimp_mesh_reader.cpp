// The only file that speaks assimp: any mesh format it imports (glTF/GLB for read_mesh, any
// scene file of the simulator), walking the node tree with transforms in double precision so
// that re-centred glTF files come back exact far from the origin.

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <utility>

#include "featsense/viewer_export/assimp_mesh_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::viewer_export {
namespace {

/// The one up-axis rule (assimp_mesh_io.hpp): glTF/GLB and COLLADA arrive Y up from assimp's
/// importers, every other format is Z up.
bool file_is_y_up(const std::string& path, const std::string& up_axis) {
  if (up_axis == "y") return true;
  if (up_axis == "z") return false;
  if (up_axis != "auto")
    throw MeshFileError(path + ": up axis must be auto, y or z, not '" + up_axis + "'");
  const std::string extension = mesh_extension(path);
  return extension == ".gltf" || extension == ".glb" || extension == ".dae";
}

Eigen::Matrix4d to_eigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d out;
  out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3,
      m.d4;
  return out;
}

uint8_t to_byte(float value) {
  return static_cast<uint8_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 255.0f));
}

float material_reflectance(const aiMaterial* material, float fallback) {
  aiColor4D colour;
  if (material == nullptr || material->Get(AI_MATKEY_COLOR_DIFFUSE, colour) != aiReturn_SUCCESS)
    return fallback;
  const float mean = (colour.r + colour.g + colour.b) / 3.0f;
  return std::clamp(mean, 0.02f, 0.98f);
}

struct Collector {
  const aiScene* scene;
  const AssimpReadOptions& options;
  bool from_y_up;
  mesh::TriangleMesh mesh;
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> colors;
  std::map<unsigned, uint32_t> part_of_mesh;  ///< assimp mesh index -> part index
  bool all_colors = true;
  bool all_normals = true;

  Eigen::Vector3d to_map(const Eigen::Vector3d& p) const {
    return from_y_up ? Eigen::Vector3d(p.x(), -p.z(), p.y()) : p;
  }

  uint32_t part_for(unsigned index) {
    const auto known = part_of_mesh.find(index);
    if (known != part_of_mesh.end()) return known->second;
    const aiMesh* part = scene->mMeshes[index];
    const aiMaterial* material = part->mMaterialIndex < scene->mNumMaterials
                                     ? scene->mMaterials[part->mMaterialIndex]
                                     : nullptr;
    const std::string name =
        part->mName.length > 0 ? part->mName.C_Str() : "mesh " + std::to_string(index);
    const uint32_t id =
        mesh.add_part(name, material_reflectance(material, options.default_reflectance));
    part_of_mesh.emplace(index, id);
    return id;
  }

  void visit(const aiNode* node, const Eigen::Matrix4d& parent) {
    const Eigen::Matrix4d T = parent * to_eigen(node->mTransformation);
    const Eigen::Matrix3d R_normal = T.topLeftCorner<3, 3>().inverse().transpose();
    for (unsigned m = 0; m < node->mNumMeshes; ++m) {
      const unsigned index = node->mMeshes[m];
      const aiMesh* part = scene->mMeshes[index];
      const bool has_triangles = (part->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) != 0;
      if (options.surfaces_only && !has_triangles) continue;
      const uint32_t part_id = has_triangles ? part_for(index) : 0;
      const int base = static_cast<int>(mesh.vertices.size());
      for (unsigned i = 0; i < part->mNumVertices; ++i) {
        const aiVector3D& v = part->mVertices[i];
        const Eigen::Vector3d p = (T * Eigen::Vector4d(v.x, v.y, v.z, 1.0)).head<3>();
        mesh.vertices.push_back((to_map(p) * options.unit_scale).cast<float>());
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
        mesh.triangle_part.push_back(part_id);
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) visit(node->mChildren[c], T);
  }
};

}  // namespace

mesh::TriangleMesh read_mesh_with_assimp(const std::string& path, MeshAttributes* attributes,
                                         const AssimpReadOptions& options) {
  if (!std::filesystem::is_regular_file(path)) throw MeshFileError(path + ": no such mesh file");
  if (!std::ifstream(path)) throw MeshFileError(path + ": cannot read the mesh file");
  if (!(options.unit_scale > 0.0) || !std::isfinite(options.unit_scale))
    throw MeshFileError(path + ": unit scale must be > 0");
  const bool from_y_up = file_is_y_up(path, options.up_axis);

  Assimp::Importer importer;
  unsigned steps = aiProcess_Triangulate;
  if (options.surfaces_only) {
    // Only triangles reflect rays: points and lines go (with SortByPType), and shared corners
    // are joined.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                                aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    steps |= aiProcess_SortByPType | aiProcess_JoinIdenticalVertices;
  }
  // Otherwise no vertex joining: the vertex order stays that of the file.
  const aiScene* scene = importer.ReadFile(path, steps);
  if (scene == nullptr || scene->mRootNode == nullptr)
    throw MeshFileError(path + ": cannot read the mesh: " + importer.GetErrorString());

  Collector collector{scene, options, from_y_up, {}, {}, {}, true, true};
  collector.visit(scene->mRootNode, Eigen::Matrix4d::Identity());
  if (!collector.all_normals) collector.mesh.normals.clear();
  if (options.surfaces_only && collector.mesh.triangles.empty())
    throw MeshFileError(path + ": the mesh holds no triangles");
  for (const Eigen::Vector3f& v : collector.mesh.vertices) {
    if (!v.allFinite()) throw MeshFileError(path + ": the mesh has non-finite vertex coordinates");
  }
  if (attributes != nullptr && collector.all_colors) attributes->colors = collector.colors;
  return std::move(collector.mesh);
}

}  // namespace featsense::viewer_export
