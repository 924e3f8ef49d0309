// The extension dispatcher: checks the mesh once, then hands it to the format's writer.

#include "featsense/viewer_export/mesh_writer.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "featsense/viewer_export/assimp_mesh_io.hpp"
#include "featsense/viewer_export/gltf_mesh_io.hpp"
#include "featsense/viewer_export/mesh_nav_h5_io.hpp"
#include "featsense/viewer_export/obj_mesh_io.hpp"

namespace featsense::viewer_export {
namespace {

constexpr const char* kWritable = ".ply, .obj, .glb, .gltf or .h5";

void check(const std::string& path, const mesh::TriangleMesh& mesh,
           const MeshAttributes& attributes) {
  if (mesh.vertices.empty()) throw MeshFileError(path + ": the mesh to write is empty");
  try {
    mesh::validate(mesh, path);
  } catch (const mesh::MeshError& error) {
    throw MeshFileError(error.what());
  }
  const size_t n = mesh.vertices.size();
  for (const VertexScalar& scalar : attributes.scalars) {
    if (scalar.values.size() != n) {
      throw MeshFileError(path + ": layer '" + scalar.name + "' has " +
                          std::to_string(scalar.values.size()) + " values for " +
                          std::to_string(n) + " vertices");
    }
  }
  if (!attributes.colors.empty() && attributes.colors.size() != n) {
    throw MeshFileError(path + ": " + std::to_string(attributes.colors.size()) + " colours for " +
                        std::to_string(n) + " vertices");
  }
}

}  // namespace

std::string mesh_extension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

bool is_writable_mesh_path(const std::string& path) {
  const std::string extension = mesh_extension(path);
  return extension == ".ply" || extension == ".obj" || extension == ".glb" ||
         extension == ".gltf" || extension == ".h5";
}

void write_mesh(const std::string& path, const mesh::TriangleMesh& mesh,
                const MeshAttributes& attributes, const MeshWriteSettings& settings) {
  const std::string extension = mesh_extension(path);
  if (!is_writable_mesh_path(path)) {
    throw MeshFileError(path + ": unknown mesh format '" + extension + "' (write " + kWritable +
                        ")");
  }
  check(path, mesh, attributes);
  if (extension == ".ply") {
    PlyWriteSettings ply;
    ply.binary = !settings.ply_ascii;
    try {
      write_ply_mesh(path, mesh, attributes, ply);
    } catch (const PlyError& error) {
      throw MeshFileError(error.what());
    }
  } else if (extension == ".obj") {
    write_obj_mesh(path, mesh, attributes);
  } else if (extension == ".glb" || extension == ".gltf") {
    write_gltf_mesh(path, mesh, attributes, extension == ".glb");
  } else {
    write_mesh_nav_h5(path, mesh, attributes);
  }
}

mesh::TriangleMesh read_mesh(const std::string& path, MeshAttributes* attributes) {
  const std::string extension = mesh_extension(path);
  if (extension == ".ply") return read_ply_mesh(path, attributes);
  if (extension == ".obj") return read_obj_mesh(path, attributes);
  if (extension == ".glb" || extension == ".gltf") return read_mesh_with_assimp(path, attributes);
  throw MeshFileError(path + ": unknown mesh format '" + extension +
                      "' (read .ply, .obj, .glb or .gltf)");
}

}  // namespace featsense::viewer_export
