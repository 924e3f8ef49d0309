// OBJ: written and read back bit for bit (vertices, normals, faces, colours), the MTL beside
// it, and the reader's other index forms.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/test_data.hpp"
#include "featsense/viewer_export/obj_mesh_io.hpp"

namespace featsense::test {
namespace {

mesh::TriangleMesh two_triangles() {
  mesh::TriangleMesh m;
  // Values with long decimal expansions and a far coordinate: 9 digits must keep them exact.
  m.vertices = {{0.1f, -0.2f, 1e-7f}, {1.0f / 3.0f, 0, 0}, {12345.678f, 1, 0.5f}, {0, 1, -0.25f}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0.6f, 0.8f}, {1, 0, 0}};
  return m;
}

TEST(ObjMeshIo, RoundTripIsExact) {
  const std::filesystem::path dir = scratch_dir("obj_round_trip");
  const mesh::TriangleMesh written = two_triangles();
  viewer_export::MeshAttributes attributes;
  attributes.colors = {{255, 0, 0}, {0, 128, 0}, {1, 2, 3}, {254, 253, 252}};
  const std::string path = (dir / "two.obj").string();
  viewer_export::write_obj_mesh(path, written, attributes);
  ASSERT_TRUE(std::filesystem::exists(dir / "two.mtl"));

  viewer_export::MeshAttributes read_attributes;
  const mesh::TriangleMesh read = viewer_export::read_obj_mesh(path, &read_attributes);
  EXPECT_EQ(read.vertices, written.vertices);
  EXPECT_EQ(read.normals, written.normals);
  EXPECT_EQ(read.triangles, written.triangles);
  EXPECT_EQ(read_attributes.colors, attributes.colors);
}

TEST(ObjMeshIo, NoColoursNoMtl) {
  const std::filesystem::path dir = scratch_dir("obj_plain");
  mesh::TriangleMesh written = two_triangles();
  written.normals.clear();
  const std::string path = (dir / "plain.obj").string();
  viewer_export::write_obj_mesh(path, written);
  EXPECT_FALSE(std::filesystem::exists(dir / "plain.mtl"));
  viewer_export::MeshAttributes read_attributes;
  const mesh::TriangleMesh read = viewer_export::read_obj_mesh(path, &read_attributes);
  EXPECT_EQ(read.vertices, written.vertices);
  EXPECT_EQ(read.triangles, written.triangles);
  EXPECT_TRUE(read.normals.empty());
  EXPECT_TRUE(read_attributes.colors.empty());
}

TEST(ObjMeshIo, ReadsOtherIndexFormsAndPolygons) {
  const std::filesystem::path dir = scratch_dir("obj_forms");
  const std::string path = (dir / "forms.obj").string();
  std::ofstream(path) << "# a quad as v/t/n with negative indices, then a triangle as v/t\n"
                         "o thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                         "f -4/1/1 -3/1/1 -2/1/1 -1/1/1\nf 1/1 3/1 4/1\n";
  const mesh::TriangleMesh read = viewer_export::read_obj_mesh(path);
  ASSERT_EQ(read.vertices.size(), 4u);
  const std::vector<Eigen::Vector3i> expected = {{0, 1, 2}, {0, 2, 3}, {0, 2, 3}};
  EXPECT_EQ(read.triangles, expected);
  ASSERT_EQ(read.normals.size(), 4u);
  EXPECT_EQ(read.normals[3], Eigen::Vector3f(0, 0, 1));
}

TEST(ObjMeshIo, BadFilesNameThePath) {
  const std::filesystem::path dir = scratch_dir("obj_bad");
  const std::string missing = (dir / "missing.obj").string();
  try {
    viewer_export::read_obj_mesh(missing);
    FAIL();
  } catch (const viewer_export::MeshFileError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos);
  }
  const std::string out_of_range = (dir / "range.obj").string();
  std::ofstream(out_of_range) << "v 0 0 0\nv 1 0 0\nf 1 2 3\n";
  EXPECT_THROW(viewer_export::read_obj_mesh(out_of_range), viewer_export::MeshFileError);
  const std::string garbage = (dir / "garbage.obj").string();
  std::ofstream(garbage) << "v 0 0 0\nv 1 0 0\nv 1 1 1\nf 1 x 3\n";
  EXPECT_THROW(viewer_export::read_obj_mesh(garbage), viewer_export::MeshFileError);
  EXPECT_THROW(
      viewer_export::write_obj_mesh((dir / "no" / "such" / "dir.obj").string(), two_triangles()),
      viewer_export::MeshFileError);
}

}  // namespace
}  // namespace featsense::test
