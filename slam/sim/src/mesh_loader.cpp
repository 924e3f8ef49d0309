// The only file that speaks assimp.
#include "featsense/slam/sim/mesh_loader.hpp"

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include "featsense/slam/scan_source.hpp"

namespace featsense::slam {
namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

/// assimp hands glTF (Y up by its specification) and COLLADA (converted to Y up from the
/// file's <up_axis>) over Y up; the other formats carry no up axis, and Z up is this
/// project's convention.
bool file_is_y_up(const std::string& path, const std::string& up_axis) {
  if (up_axis == "y") return true;
  if (up_axis == "z") return false;
  if (up_axis != "auto") throw InputError("up axis must be auto, y or z, not '" + up_axis + "'");
  const std::string ext = lower_extension(path);
  return ext == ".gltf" || ext == ".glb" || ext == ".dae";
}

float material_reflectance(const aiMaterial* material, float fallback) {
  aiColor4D colour;
  if (material == nullptr || material->Get(AI_MATKEY_COLOR_DIFFUSE, colour) != aiReturn_SUCCESS)
    return fallback;
  const float mean = (colour.r + colour.g + colour.b) / 3.0f;
  return std::clamp(mean, 0.02f, 0.98f);
}

}  // namespace

mesh::TriangleMesh load_mesh(const std::string& path, const MeshLoadOptions& options) {
  if (!std::filesystem::is_regular_file(path)) throw InputError(path + ": no such mesh file");
  if (!std::ifstream(path)) throw InputError(path + ": cannot read the mesh file");
  if (!(options.unit_scale > 0.0)) throw InputError(path + ": unit scale must be > 0");
  const bool y_up = file_is_y_up(path, options.up_axis);

  Assimp::Importer importer;
  // Drop points and lines: only triangles reflect rays.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices |
                                  aiProcess_SortByPType | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr)
    throw InputError(path + ": cannot read the mesh: " + importer.GetErrorString());

  mesh::TriangleMesh mesh;
  const float scale = static_cast<float>(options.unit_scale);
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* part = scene->mMeshes[m];
    if (!(part->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    const aiMaterial* material = part->mMaterialIndex < scene->mNumMaterials
                                     ? scene->mMaterials[part->mMaterialIndex]
                                     : nullptr;
    const std::string name =
        part->mName.length > 0 ? part->mName.C_Str() : "mesh " + std::to_string(m);
    const uint32_t id =
        mesh.add_part(name, material_reflectance(material, options.default_reflectance));
    const int first = static_cast<int>(mesh.vertices.size());
    for (unsigned v = 0; v < part->mNumVertices; ++v) {
      const aiVector3D& p = part->mVertices[v];
      // Y up to Z up: a +90 deg turn about x, (x, y, z) -> (x, -z, y).
      mesh.vertices.push_back(y_up ? Eigen::Vector3f(p.x, -p.z, p.y) * scale
                                   : Eigen::Vector3f(p.x, p.y, p.z) * scale);
    }
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      const aiFace& face = part->mFaces[f];
      if (face.mNumIndices != 3) continue;
      mesh.triangles.emplace_back(first + static_cast<int>(face.mIndices[0]),
                                  first + static_cast<int>(face.mIndices[1]),
                                  first + static_cast<int>(face.mIndices[2]));
      mesh.triangle_part.push_back(id);
    }
  }
  if (mesh.triangles.empty()) throw InputError(path + ": the mesh holds no triangles");
  for (const Eigen::Vector3f& v : mesh.vertices) {
    if (!v.allFinite()) throw InputError(path + ": the mesh has non-finite vertex coordinates");
  }
  return mesh;
}

}  // namespace featsense::slam
