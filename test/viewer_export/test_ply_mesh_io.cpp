#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

#include "common/test_data.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"

namespace featsense::test {
namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const viewer_export::PlyError& e) {
    return e.what();
  }
  return "";
}

mesh::TriangleMesh two_triangles() {
  mesh::TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.5f}, {0, 1, -0.25f}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0.6f, 0.8f}, {1, 0, 0}};
  return m;
}

void expect_same(const mesh::TriangleMesh& a, const mesh::TriangleMesh& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  ASSERT_EQ(a.normals.size(), b.normals.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) EXPECT_EQ(a.vertices[i], b.vertices[i]) << i;
  for (size_t i = 0; i < a.normals.size(); ++i) EXPECT_EQ(a.normals[i], b.normals[i]) << i;
  for (size_t i = 0; i < a.triangles.size(); ++i) EXPECT_EQ(a.triangles[i], b.triangles[i]) << i;
}

TEST(PlyMeshIo, BinaryAndAsciiRoundTrips) {
  const auto dir = scratch_dir("ply_mesh_round_trip");
  const mesh::TriangleMesh m = two_triangles();
  viewer_export::MeshAttributes attributes;
  attributes.scalars.push_back({"distance", {0.5f, 0.25f, 0.125f, 1.0f}});
  attributes.colors = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {1, 2, 3}};
  for (bool binary : {true, false}) {
    const std::string path = (dir / (binary ? "b.ply" : "a.ply")).string();
    viewer_export::write_ply_mesh(path, m, attributes, {binary});
    expect_same(viewer_export::read_ply_mesh(path), m);
    std::ostringstream text;
    text << std::ifstream(path, std::ios::binary).rdbuf();
    const std::string header = text.str();
    EXPECT_NE(header.find("property float scalar_distance"), std::string::npos);
    EXPECT_NE(header.find(binary ? "binary_little_endian" : "format ascii"), std::string::npos);
  }
}

TEST(PlyMeshIo, ReadsAnyTypesQuadsAndOtherElements) {
  const auto dir = scratch_dir("ply_mesh_types");
  const std::string path = (dir / "quad.ply").string();
  std::ofstream(path) << "ply\nformat ascii 1.0\ncomment a quad\n"
                         "element vertex 4\nproperty double x\nproperty int y\nproperty float z\n"
                         "property uchar red\n"
                         "element face 1\nproperty list uint short vertex_index\n"
                         "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
                         "end_header\n"
                         "0.5 0 1 7\n1.5 0 1 7\n1.5 2 1 7\n0.5 2 1 7\n4 0 1 2 3\n0 1\n";
  const mesh::TriangleMesh m = viewer_export::read_ply_mesh(path);
  ASSERT_EQ(m.vertices.size(), 4u);
  EXPECT_EQ(m.vertices[2], Eigen::Vector3f(1.5f, 2, 1));
  ASSERT_EQ(m.triangles.size(), 2u);  // the quad as a fan
  EXPECT_EQ(m.triangles[1], Eigen::Vector3i(0, 2, 3));
  EXPECT_TRUE(m.normals.empty());
}

TEST(PlyMeshIo, ReadsBigEndianPointClouds) {
  const auto dir = scratch_dir("ply_mesh_big_endian");
  const std::string path = (dir / "be.ply").string();
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_big_endian 1.0\nelement vertex 2\nproperty float x\n"
         "property float y\nproperty float z\nproperty ushort intensity\nend_header\n";
  const float values[2][3] = {{1.0f, -2.0f, 0.5f}, {3.25f, 0.0f, -8.0f}};
  for (const auto& v : values) {
    for (float f : v) {
      uint32_t bits = 0;
      std::memcpy(&bits, &f, 4);
      const char bytes[4] = {static_cast<char>(bits >> 24), static_cast<char>(bits >> 16),
                             static_cast<char>(bits >> 8), static_cast<char>(bits)};
      out.write(bytes, 4);
    }
    out.write("\x01\x02", 2);
  }
  out.close();
  const mesh::TriangleMesh m = viewer_export::read_ply_mesh(path);
  ASSERT_EQ(m.vertices.size(), 2u);
  EXPECT_TRUE(m.is_point_cloud());
  EXPECT_EQ(m.vertices[1], Eigen::Vector3f(3.25f, 0.0f, -8.0f));
}

TEST(PlyMeshIo, ErrorsNameTheFile) {
  const auto dir = scratch_dir("ply_mesh_errors");
  const std::string path = (dir / "bad.ply").string();
  std::ofstream(path) << "not a ply\n";
  EXPECT_NE(error_of([&] { viewer_export::read_ply_mesh(path); }).find(path + ": not a PLY"),
            std::string::npos);
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                         "property float y\nproperty float z\nend_header\n0 0 0\n1 1\n";
  EXPECT_NE(error_of([&] { viewer_export::read_ply_mesh(path); }).find("expected a number"),
            std::string::npos);
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                         "property float y\nproperty float z\nelement face 1\n"
                         "property list uchar int vertex_indices\nend_header\n0 0 0\n3 0 1 2\n";
  EXPECT_NE(error_of([&] { viewer_export::read_ply_mesh(path); }).find("refers to vertex 1"),
            std::string::npos);
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                         "property float y\nproperty float z\nelement face 1\n"
                         "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n"
                         "0 1 0\n3 0 1 -2\n";
  EXPECT_NE(error_of([&] { viewer_export::read_ply_mesh(path); }).find("vertex index out of range"),
            std::string::npos);
  std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n";
  EXPECT_NE(error_of([&] { viewer_export::read_ply_mesh(path); }).find("no end_header"),
            std::string::npos);
  mesh::TriangleMesh m = two_triangles();
  viewer_export::MeshAttributes attributes;
  attributes.scalars.push_back({"short", {1.0f}});
  EXPECT_NE(error_of([&] {
              viewer_export::write_ply_mesh(path, m, attributes);
            }).find("layer 'short' has 1 values for 4 vertices"),
            std::string::npos);
}

}  // namespace
}  // namespace featsense::test
