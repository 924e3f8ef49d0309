// HDF5 writer of the mesh navigation layout, through the HDF5 C API (headers only here).

#include <hdf5.h>

#include "featsense/mesh/navigation_layers.hpp"
#include "featsense/viewer_export/mesh_nav_h5_io.hpp"

namespace featsense::viewer_export {
namespace {

/// Closes an HDF5 handle when it goes out of scope.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t), const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) throw MeshFileError(what);
  }
  ~Handle() { close_(id_); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t get() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

Handle make_group(hid_t parent, const std::string& name, const std::string& path) {
  return Handle(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                path + ": cannot create group " + name);
}

void string_attribute(hid_t object, const std::string& name, const std::string& value,
                      const std::string& path) {
  const Handle type(H5Tcopy(H5T_C_S1), H5Tclose, path + ": HDF5 type");
  H5Tset_size(type.get(), value.size());
  const Handle space(H5Screate(H5S_SCALAR), H5Sclose, path + ": HDF5 space");
  const Handle attribute(
      H5Acreate2(object, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
      path + ": cannot create attribute " + name);
  if (H5Awrite(attribute.get(), type.get(), value.data()) < 0) {
    throw MeshFileError(path + ": cannot write attribute " + name);
  }
}

/// A rows x columns dataset of `memory_type` (float32 or uint32 in the file).
void dataset(hid_t group, const std::string& name, const void* data, hsize_t rows, hsize_t columns,
             hid_t file_type, hid_t memory_type, const std::string& path) {
  const hsize_t dims[2] = {rows, columns};
  const Handle space(H5Screate_simple(2, dims, nullptr), H5Sclose, path + ": HDF5 space");
  const Handle set(H5Dcreate2(group, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT,
                              H5P_DEFAULT),
                   H5Dclose, path + ": cannot create dataset " + name);
  if (rows > 0 && H5Dwrite(set.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    throw MeshFileError(path + ": cannot write dataset " + name);
  }
}

}  // namespace

void write_mesh_nav_h5(const std::string& path, const mesh::TriangleMesh& mesh,
                       const MeshAttributes& attributes,
                       const std::vector<FaceScalar>& face_scalars, const std::string& part) {
  const size_t n = mesh.vertices.size();
  for (const VertexScalar& scalar : attributes.scalars) {
    if (scalar.values.size() != n) {
      throw MeshFileError(path + ": layer '" + scalar.name + "' does not match the vertices");
    }
  }
  for (const FaceScalar& scalar : face_scalars) {
    if (scalar.values.size() != mesh.triangles.size()) {
      throw MeshFileError(path + ": face layer '" + scalar.name + "' does not match the faces");
    }
  }
  const std::vector<Eigen::Vector3f> normals = mesh::vertex_normals(mesh);
  std::vector<uint32_t> faces;
  faces.reserve(3 * mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) faces.push_back(static_cast<uint32_t>(t[k]));
  }

  // Silence HDF5's own error printing: failures come back as our exceptions.
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose,
                    path + ": cannot create the HDF5 file");
  const Handle root = make_group(file.get(), part, path);
  string_attribute(root.get(), "IO", "MeshIO", path);
  string_attribute(root.get(), "CLASS", "MeshBuffer", path);
  const Handle geometry = make_group(root.get(), "geometry", path);
  dataset(geometry.get(), "vertices", mesh.vertices.data(), n, 3, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT,
          path);
  dataset(geometry.get(), "face_indices", faces.data(), mesh.triangles.size(), 3, H5T_STD_U32LE,
          H5T_NATIVE_UINT32, path);
  const Handle vertex_attributes = make_group(root.get(), "vertex_attributes", path);
  dataset(vertex_attributes.get(), "vertex_normals", normals.data(), n, 3, H5T_IEEE_F32LE,
          H5T_NATIVE_FLOAT, path);
  for (const VertexScalar& scalar : attributes.scalars) {
    dataset(vertex_attributes.get(), scalar.name, scalar.values.data(), n, 1, H5T_IEEE_F32LE,
            H5T_NATIVE_FLOAT, path);
  }
  const Handle face_attributes = make_group(root.get(), "face_attributes", path);
  for (const FaceScalar& scalar : face_scalars) {
    dataset(face_attributes.get(), scalar.name, scalar.values.data(), mesh.triangles.size(), 1,
            H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, path);
  }
}

}  // namespace featsense::viewer_export
