// The viewer's mesh binary: its header, its blocks where the page looks for them, its checks.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>

#include "featsense/viewer_export/mesh_file_error.hpp"
#include "featsense/viewer_export/viewer_mesh_binary.hpp"

namespace featsense::test {
namespace {

template <typename T>
T read_at(const std::string& bytes, size_t offset) {
  T value{};
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

mesh::TriangleMesh one_triangle() {
  mesh::TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 2}};
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  m.triangles = {{0, 1, 2}};
  return m;
}

TEST(ViewerMeshBinary, HeaderAndBlocksAsDocumented) {
  const mesh::TriangleMesh m = one_triangle();
  const std::string bytes =
      viewer_export::encode_viewer_mesh(m, {{"cost", {0.0f, 0.5f, 1.0f}}, {"e", {1, 2, 3}}});
  ASSERT_EQ(bytes.size(), viewer_export::viewer_mesh_bytes(3, 1, 2));
  // Normals: 9 bytes padded to 12.
  ASSERT_EQ(bytes.size(), 32u + 3 * 3 * 4 + 12 + 3 * 4 + 2 * 3 * 4);
  EXPECT_EQ(std::string(bytes.data(), 8), std::string("FSVIEW1\0", 8));
  EXPECT_EQ(read_at<uint32_t>(bytes, 8), 3u);
  EXPECT_EQ(read_at<uint32_t>(bytes, 12), 1u);
  EXPECT_EQ(read_at<uint32_t>(bytes, 16), 2u);
  const size_t positions = 32;
  const size_t normals = positions + 36;
  const size_t indices = normals + 12;
  const size_t layers = indices + 12;
  EXPECT_EQ(read_at<float>(bytes, positions + 4 * (3 * 2 + 2)), 2.0f);  // z of the third vertex
  EXPECT_EQ(read_at<int8_t>(bytes, normals + 2), 127);                  // +Z
  EXPECT_EQ(read_at<int8_t>(bytes, normals + 0), 0);
  EXPECT_EQ(read_at<int8_t>(bytes, normals + 9), 0);  // padding
  EXPECT_EQ(read_at<uint32_t>(bytes, indices + 8), 2u);
  EXPECT_EQ(read_at<float>(bytes, layers + 4), 0.5f);
  EXPECT_EQ(read_at<float>(bytes, layers + 12 + 8), 3.0f);
}

TEST(ViewerMeshBinary, MismatchedNormalsOrLayersThrow) {
  mesh::TriangleMesh m = one_triangle();
  EXPECT_THROW(viewer_export::encode_viewer_mesh(m, {{"short", {1.0f}}}),
               viewer_export::MeshFileError);
  m.normals.clear();
  EXPECT_THROW(viewer_export::encode_viewer_mesh(m, {}), viewer_export::MeshFileError);
}

}  // namespace
}  // namespace featsense::test
