// The extension dispatcher's errors, and the mesh navigation HDF5 read back through the C API.

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>

#include "common/test_data.hpp"
#include "featsense/viewer_export/mesh_nav_h5_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::test {
namespace {

mesh::TriangleMesh two_triangles() {
  mesh::TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5f}, {0, 1, -0.25f}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const viewer_export::MeshFileError& e) {
    return e.what();
  }
  return "";
}

TEST(MeshWriter, BadInputGivesClearErrors) {
  const std::filesystem::path dir = scratch_dir("mesh_writer_bad");
  const std::string unknown = (dir / "mesh.stl").string();
  EXPECT_NE(error_of([&] {
              viewer_export::write_mesh(unknown, two_triangles());
            }).find("unknown mesh format '.stl'"),
            std::string::npos);
  for (const std::string extension : {".ply", ".obj", ".glb", ".gltf", ".h5"}) {
    const std::string path = (dir / ("mesh" + extension)).string();
    EXPECT_NE(error_of([&] {
                viewer_export::write_mesh(path, mesh::TriangleMesh{});
              }).find(path + ": the mesh to write is empty"),
              std::string::npos);
    mesh::TriangleMesh with_nan = two_triangles();
    with_nan.vertices[2].y() = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NE(error_of([&] { viewer_export::write_mesh(path, with_nan); }).find("non-finite"),
              std::string::npos);
    viewer_export::MeshAttributes short_layer;
    short_layer.scalars = {{"cost", {1.0f}}};
    EXPECT_NE(error_of([&] {
                viewer_export::write_mesh(path, two_triangles(), short_layer);
              }).find("layer 'cost' has 1 values for 4 vertices"),
              std::string::npos);
    const std::string unwritable = (dir / "no" / "such" / ("mesh" + extension)).string();
    EXPECT_NE(
        error_of([&] { viewer_export::write_mesh(unwritable, two_triangles()); }).find(unwritable),
        std::string::npos)
        << extension;
  }
}

TEST(MeshWriter, PlyRoundTripKeepsColoursAndLayers) {
  const std::filesystem::path dir = scratch_dir("mesh_writer_ply_layers");
  viewer_export::MeshAttributes attributes;
  attributes.colors = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}, {250, 251, 252}};
  attributes.scalars = {{"inclination_deg", {0.5f, 1.0f / 3.0f, 45.0f, -2.0f}},
                        {"cost", {0.0f, 0.25f, 1.0f, 0.75f}}};
  for (const bool ascii : {false, true}) {
    const std::string path = (dir / (ascii ? "ascii.ply" : "binary.ply")).string();
    viewer_export::MeshWriteSettings settings;
    settings.ply_ascii = ascii;
    viewer_export::write_mesh(path, two_triangles(), attributes, settings);
    viewer_export::MeshAttributes read_attributes;
    const mesh::TriangleMesh read = viewer_export::read_mesh(path, &read_attributes);
    EXPECT_EQ(read.vertices, two_triangles().vertices);
    EXPECT_EQ(read.triangles, two_triangles().triangles);
    EXPECT_EQ(read_attributes.colors, attributes.colors);
    ASSERT_EQ(read_attributes.scalars.size(), 2u);
    for (size_t k = 0; k < 2; ++k) {
      EXPECT_EQ(read_attributes.scalars[k].name, attributes.scalars[k].name);
      EXPECT_EQ(read_attributes.scalars[k].values, attributes.scalars[k].values) << ascii;
    }
  }
}

TEST(MeshWriter, PlyAndObjRoundTripThroughTheDispatcher) {
  const std::filesystem::path dir = scratch_dir("mesh_writer_round_trip");
  viewer_export::MeshAttributes attributes;
  attributes.colors = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}, {250, 251, 252}};
  for (const std::string name : {"a.ply", "b.PLY", "c.obj"}) {
    const std::string path = (dir / name).string();
    viewer_export::write_mesh(path, two_triangles(), attributes);
    const mesh::TriangleMesh read = viewer_export::read_mesh(path);
    EXPECT_EQ(read.vertices, two_triangles().vertices) << name;
    EXPECT_EQ(read.triangles, two_triangles().triangles) << name;
  }
  EXPECT_THROW(viewer_export::read_mesh((dir / "x.h5").string()), viewer_export::MeshFileError);
}

/// Reads an N x columns float or uint dataset.
template <typename T>
std::vector<T> read_dataset(hid_t file, const std::string& name, hid_t type, hsize_t* rows,
                            hsize_t* columns) {
  const hid_t set = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  EXPECT_GE(set, 0) << name;
  const hid_t space = H5Dget_space(set);
  hsize_t dims[2] = {0, 0};
  EXPECT_EQ(H5Sget_simple_extent_ndims(space), 2);
  H5Sget_simple_extent_dims(space, dims, nullptr);
  *rows = dims[0];
  *columns = dims[1];
  std::vector<T> values(dims[0] * dims[1]);
  H5Dread(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Sclose(space);
  H5Dclose(set);
  return values;
}

std::string string_attribute(hid_t object, const std::string& name) {
  const hid_t attribute = H5Aopen(object, name.c_str(), H5P_DEFAULT);
  const hid_t type = H5Aget_type(attribute);
  std::string value(H5Tget_size(type), '\0');
  H5Aread(attribute, type, value.data());
  H5Tclose(type);
  H5Aclose(attribute);
  return value;
}

TEST(MeshNavH5, LayoutReadsBack) {
  const std::filesystem::path dir = scratch_dir("mesh_nav_h5");
  const std::string path = (dir / "nav.h5").string();
  viewer_export::MeshAttributes attributes;
  attributes.scalars = {{"cost", {0.0f, 0.5f, 1.0f, 0.25f}}};
  viewer_export::write_mesh_nav_h5(path, two_triangles(), attributes, {{"lethal", {0.0f, 1.0f}}});

  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t part = H5Gopen2(file, "mesh", H5P_DEFAULT);
  EXPECT_EQ(string_attribute(part, "IO"), "MeshIO");
  EXPECT_EQ(string_attribute(part, "CLASS"), "MeshBuffer");
  H5Gclose(part);
  hsize_t rows = 0;
  hsize_t columns = 0;
  const auto vertices =
      read_dataset<float>(file, "mesh/geometry/vertices", H5T_NATIVE_FLOAT, &rows, &columns);
  EXPECT_EQ(rows, 4u);
  EXPECT_EQ(columns, 3u);
  EXPECT_EQ(vertices, std::vector<float>({0, 0, 0, 1, 0, 0, 1, 1, 0.5f, 0, 1, -0.25f}));
  const auto faces = read_dataset<uint32_t>(file, "mesh/geometry/face_indices", H5T_NATIVE_UINT32,
                                            &rows, &columns);
  EXPECT_EQ(faces, std::vector<uint32_t>({0, 1, 2, 0, 2, 3}));
  const auto normals = read_dataset<float>(file, "mesh/vertex_attributes/vertex_normals",
                                           H5T_NATIVE_FLOAT, &rows, &columns);
  EXPECT_EQ(rows, 4u);
  EXPECT_EQ(columns, 3u);
  // Vertex 1 lies only in the first face, (1,0,0)x(1,1,0.5) normalised: (0,-0.5,1)/sqrt(1.25).
  EXPECT_NEAR(normals[3], 0.0f, 1e-6f);
  EXPECT_NEAR(normals[4], -0.5f / std::sqrt(1.25f), 1e-6f);
  EXPECT_NEAR(normals[5], 1.0f / std::sqrt(1.25f), 1e-6f);
  const auto cost =
      read_dataset<float>(file, "mesh/vertex_attributes/cost", H5T_NATIVE_FLOAT, &rows, &columns);
  EXPECT_EQ(cost, attributes.scalars[0].values);
  EXPECT_EQ(columns, 1u);
  const auto lethal =
      read_dataset<float>(file, "mesh/face_attributes/lethal", H5T_NATIVE_FLOAT, &rows, &columns);
  EXPECT_EQ(lethal, std::vector<float>({0.0f, 1.0f}));
  H5Fclose(file);
}

}  // namespace
}  // namespace featsense::test
