// The mesh type's builders, parts and checks.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <string>
#include <vector>

#include "featsense/mesh/mesh_simplification.hpp"
#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::test {
namespace {

using V = Eigen::Vector3f;

TEST(TriangleMesh, BoxIsClosedFacingInwardsWithItsPart) {
  mesh::TriangleMesh m;
  m.add_part("unused", 0.1f);
  const uint32_t wall = m.add_part("wall", 0.6f);
  m.add_box(V(-1, -2, 0), V(3, 2, 2.5f), wall);
  ASSERT_EQ(m.triangle_count(), 12u);
  ASSERT_TRUE(m.has_parts());
  EXPECT_FALSE(m.has_normals());
  EXPECT_NO_THROW(mesh::validate(m, "box"));
  EXPECT_NEAR(mesh::surface_area_m2(m), 2 * (4 * 4 + 4 * 2.5 + 4 * 2.5), 1e-4);
  const Eigen::Vector3f centre(1, 0, 1.25f);
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    EXPECT_FLOAT_EQ(m.reflectance(t), 0.6f);
    const Eigen::Vector3i& tri = m.triangles[t];
    const V a = m.vertices[static_cast<size_t>(tri[0])];
    const V n = (m.vertices[static_cast<size_t>(tri[1])] - a)
                    .cross(m.vertices[static_cast<size_t>(tri[2])] - a);
    EXPECT_LT(n.dot(a - centre), 0.0f) << "triangle " << t << " faces outwards";
  }
  V lo, hi;
  m.bounds(&lo, &hi);
  EXPECT_EQ(lo, V(-1, -2, 0));
  EXPECT_EQ(hi, V(3, 2, 2.5f));
}

TEST(TriangleMesh, CylinderSidesAndCaps) {
  mesh::TriangleMesh m;
  m.add_cylinder(V(1, 1, 0), 0.5f, 2.0f, 16, m.add_part("pole", 0.3f));
  ASSERT_EQ(m.triangle_count(), 16u * 4u);
  const Eigen::Vector3f centre(1, 1, 1);
  for (const Eigen::Vector3i& tri : m.triangles) {
    const V a = m.vertices[static_cast<size_t>(tri[0])];
    const V n = (m.vertices[static_cast<size_t>(tri[1])] - a)
                    .cross(m.vertices[static_cast<size_t>(tri[2])] - a);
    EXPECT_GT(n.dot(a - centre), 0.0f) << "a triangle faces inwards";
  }
  V lo, hi;
  m.bounds(&lo, &hi);
  EXPECT_NEAR(lo.x(), 0.5f, 1e-6f);
  EXPECT_NEAR(hi.z(), 2.0f, 1e-6f);
  // 16 sides: the area of the inscribed polygon's caps and of its side.
  const double side = 2 * 0.5 * std::sin(M_PI / 16);
  EXPECT_NEAR(mesh::surface_area_m2(m), 16 * side * 2.0 + 2 * 16 * 0.5 * 0.25 * std::sin(M_PI / 8),
              1e-4);
}

TEST(TriangleMesh, AppendRenumbersVerticesAndParts) {
  mesh::TriangleMesh a;
  a.add_triangle(V(0, 0, 0), V(1, 0, 0), V(0, 1, 0), a.add_part("a", 0.2f));
  mesh::TriangleMesh b;
  b.add_part("b0", 0.3f);
  b.add_quad(V(0, 0, 1), V(1, 0, 1), V(1, 1, 1), V(0, 1, 1), b.add_part("b1", 0.4f));
  a.append(b);
  ASSERT_EQ(a.triangle_count(), 3u);
  ASSERT_EQ(a.parts.size(), 3u);
  EXPECT_EQ(a.triangles[1], Eigen::Vector3i(3, 4, 5));
  EXPECT_EQ(a.triangles[2], Eigen::Vector3i(3, 5, 6));
  EXPECT_EQ(a.triangle_part, (std::vector<uint32_t>{0, 2, 2}));
  EXPECT_FLOAT_EQ(a.reflectance(2), 0.4f);
  EXPECT_NO_THROW(mesh::validate(a, "appended"));

  // Triangles with parts and triangles without do not mix.
  mesh::TriangleMesh plain;
  plain.vertices = {V(0, 0, 0), V(1, 0, 0), V(0, 1, 0)};
  plain.triangles = {{0, 1, 2}};
  EXPECT_THROW(a.append(plain), mesh::MeshError);
  EXPECT_THROW(plain.append(a), mesh::MeshError);
}

TEST(TriangleMesh, AppendKeepsNormalsOnlyWhereBothHaveThem) {
  mesh::TriangleMesh with;
  with.vertices = {V(0, 0, 0), V(1, 0, 0), V(0, 1, 0)};
  with.triangles = {{0, 1, 2}};
  with.normals.assign(3, V(0, 0, 1));
  mesh::TriangleMesh m;
  m.append(with);
  EXPECT_TRUE(m.has_normals());
  m.append(with);
  EXPECT_TRUE(m.has_normals());
  EXPECT_EQ(m.normals.size(), 6u);
  mesh::TriangleMesh without = with;
  without.normals.clear();
  m.append(without);
  EXPECT_FALSE(m.has_normals());
  EXPECT_TRUE(m.normals.empty());
}

TEST(TriangleMesh, WithoutPartsTrianglesReflectTheDefault) {
  mesh::TriangleMesh m;
  m.vertices = {V(0, 0, 0), V(1, 0, 0), V(0, 1, 0)};
  m.triangles = {{0, 1, 2}};
  EXPECT_FALSE(m.has_parts());
  EXPECT_FLOAT_EQ(m.reflectance(0), mesh::MeshPart::kDefaultReflectance);
  EXPECT_NO_THROW(mesh::validate(m, "plain"));
}

std::string validation_error(const mesh::TriangleMesh& m) {
  try {
    mesh::validate(m, "scene");
  } catch (const mesh::MeshError& e) {
    return e.what();
  }
  return "";
}

TEST(TriangleMesh, ValidateChecksTheParts) {
  mesh::TriangleMesh m;
  m.add_quad(V(0, 0, 0), V(1, 0, 0), V(1, 1, 0), V(0, 1, 0), m.add_part("floor", 0.4f));
  mesh::TriangleMesh short_parts = m;
  short_parts.triangle_part.pop_back();
  EXPECT_EQ(validation_error(short_parts), "scene: 1 part indices for 2 triangles");
  mesh::TriangleMesh bad_index = m;
  bad_index.triangle_part[1] = 1;
  EXPECT_EQ(validation_error(bad_index), "scene: triangle 1 belongs to part 1 of 1");
  mesh::TriangleMesh bright = m;
  bright.parts[0].reflectance = 1.5f;
  EXPECT_NE(validation_error(bright).find("part 'floor' has the reflectance 1.5"),
            std::string::npos)
      << validation_error(bright);
}

TEST(TriangleMesh, ASubsetKeepsItsTrianglesAndOnlyTheirVertices) {
  mesh::TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {5, 5, 5}};
  m.normals.assign(5, Eigen::Vector3f::UnitZ());
  m.normals[3] = Eigen::Vector3f::UnitX();
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  std::vector<uint64_t> source;
  const mesh::TriangleMesh sub = mesh::triangle_subset(m, {1}, &source);
  // Vertices 0, 2, 3 in the order of first use; 1 and the loose 4 left out.
  EXPECT_EQ(source, (std::vector<uint64_t>{0, 2, 3}));
  ASSERT_EQ(sub.vertices.size(), 3u);
  EXPECT_EQ(sub.vertices[2], m.vertices[3]);
  EXPECT_EQ(sub.normals[2], Eigen::Vector3f::UnitX());
  ASSERT_EQ(sub.triangles.size(), 1u);
  EXPECT_EQ(sub.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_TRUE(mesh::triangle_subset(m, {}).vertices.empty());
}

TEST(TriangleMesh, TrianglesMeetingABoxKeepEveryFaceOfTheVerticesInIt) {
  // A fan of 8 triangles around the origin and a far triangle: a box around the centre alone
  // keeps the whole fan (each face holds the centre), a box off to one side only what it meets.
  mesh::TriangleMesh m;
  m.vertices.push_back(Eigen::Vector3f::Zero());
  for (int k = 0; k < 8; ++k) {
    const float a = static_cast<float>(k) * 3.14159265f / 4.0f;
    m.vertices.emplace_back(std::cos(a), std::sin(a), 0.0f);
  }
  for (int k = 0; k < 8; ++k) m.triangles.emplace_back(0, 1 + k, 1 + (k + 1) % 8);
  m.vertices.emplace_back(10.0f, 10.0f, 0.0f);
  m.vertices.emplace_back(11.0f, 10.0f, 0.0f);
  m.vertices.emplace_back(10.0f, 11.0f, 0.0f);
  m.triangles.emplace_back(9, 10, 11);
  const Eigen::AlignedBox3d centre(Eigen::Vector3d(-0.01, -0.01, -0.01),
                                   Eigen::Vector3d(0.01, 0.01, 0.01));
  EXPECT_EQ(mesh::triangles_meeting(m, centre).triangles.size(), 8u);
  const Eigen::AlignedBox3d right(Eigen::Vector3d(0.9, -0.1, -0.1), Eigen::Vector3d(2, 0.1, 0.1));
  const mesh::TriangleMesh kept = mesh::triangles_meeting(m, right);
  ASSERT_EQ(kept.triangles.size(), 2u);  // both faces of (1, 0, 0)
  // The vertices in the mesh's order (0, 1, 2, 8), whatever the order of the faces (7, 0).
  ASSERT_EQ(kept.vertices.size(), 4u);
  EXPECT_EQ(kept.vertices[3], m.vertices[8]);
  EXPECT_EQ(kept.triangles[0], Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(kept.triangles[1], Eigen::Vector3i(0, 3, 1));
  const Eigen::AlignedBox3d nowhere(Eigen::Vector3d(5, 5, 5), Eigen::Vector3d(6, 6, 6));
  EXPECT_TRUE(mesh::triangles_meeting(m, nowhere).vertices.empty());
}

TEST(TriangleMesh, WeldingKeepsNormalsPastAnEmptyPart) {
  // A part with nothing in it (no triangles of a neighbour near a tile) does not cost the
  // others their normals; a part with vertices and no normals does.
  mesh::TriangleMesh a;
  a.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  a.normals.assign(3, Eigen::Vector3f::UnitX());
  a.triangles = {{0, 1, 2}};
  mesh::TriangleMesh b = a;
  b.vertices[2] = {1, 1, 0};
  const mesh::TriangleMesh empty;
  const mesh::TriangleMesh welded = mesh::weld_by_position({&a, &empty, &b});
  EXPECT_EQ(welded.vertices.size(), 4u);
  ASSERT_TRUE(welded.has_normals());
  EXPECT_EQ(welded.normals[3], Eigen::Vector3f::UnitX());
  b.normals.clear();
  EXPECT_FALSE(mesh::weld_by_position({&a, &empty, &b}).has_normals());
  EXPECT_TRUE(mesh::weld_by_position({&empty}).vertices.empty());
}

}  // namespace
}  // namespace featsense::test
