// Foreign mesh files through assimp: PLY, OBJ (+ MTL) and COLLADA written here, the up-axis
// rule and the unit scale, parts from materials, the simulator's surfaces-only reading, the
// shared real scenes, bad input.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/test_data.hpp"
#include "featsense/viewer_export/assimp_mesh_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::test {
namespace {

using viewer_export::AssimpReadOptions;
using viewer_export::read_mesh_with_assimp;

/// What the simulator reads a scene file with.
AssimpReadOptions surfaces(const std::string& up_axis = "auto", double unit_scale = 1.0) {
  AssimpReadOptions options;
  options.surfaces_only = true;
  options.up_axis = up_axis;
  options.unit_scale = unit_scale;
  return options;
}

mesh::TriangleMesh load_surfaces(const std::string& path) {
  return read_mesh_with_assimp(path, nullptr, surfaces());
}

const char* const kBoxPly =
    "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
    "property float z\nelement face 12\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n2 0 0\n2 3 0\n0 3 0\n0 0 4\n2 0 4\n2 3 4\n0 3 4\n"
    "3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n3 1 2 6\n3 1 6 5\n"
    "3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";

std::string write_file(const std::filesystem::path& dir, const std::string& name,
                       const std::string& text) {
  const std::string path = (dir / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

TEST(AssimpMeshReader, ReadsAPlyBoxWithItsSizeAndOnePart) {
  const auto dir = scratch_dir("assimp_ply");
  const mesh::TriangleMesh mesh = load_surfaces(write_file(dir, "box.ply", kBoxPly));
  EXPECT_EQ(mesh.triangle_count(), 12u);
  EXPECT_EQ(mesh.vertices.size(), 8u);  // shared corners joined
  Eigen::Vector3f lo, hi;
  mesh.bounds(&lo, &hi);
  EXPECT_TRUE(lo.isApprox(Eigen::Vector3f(0, 0, 0)));
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(2, 3, 4)));
  ASSERT_TRUE(mesh.has_parts());
  ASSERT_EQ(mesh.parts.size(), 1u);
  // assimp gives a material without a diffuse colour of its own a mid grey.
  EXPECT_GE(mesh.reflectance(0), 0.02f);
  EXPECT_LE(mesh.reflectance(0), 0.98f);
  EXPECT_NO_THROW(mesh::validate(mesh, "box"));
}

TEST(AssimpMeshReader, ObjWithUnitScaleAndUpAxis) {
  const auto dir = scratch_dir("assimp_obj_axes");
  // One triangle in centimetres, its apex 200 cm along the file's y axis.
  const std::string obj = "v 0 0 0\nv 100 0 0\nv 0 200 0\nf 1 2 3\n";
  const std::string path = write_file(dir, "tri.obj", obj);
  mesh::TriangleMesh mesh = read_mesh_with_assimp(path, nullptr, surfaces("z", 0.01));
  ASSERT_EQ(mesh.triangle_count(), 1u);
  Eigen::Vector3f lo, hi;
  mesh.bounds(&lo, &hi);
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(1, 2, 0)));
  // "auto" takes an OBJ as Z up.
  mesh = read_mesh_with_assimp(path, nullptr, surfaces("auto", 0.01));
  mesh.bounds(&lo, &hi);
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(1, 2, 0)));
  // The file's y is up: it becomes z.
  mesh = read_mesh_with_assimp(path, nullptr, surfaces("y", 0.01));
  mesh.bounds(&lo, &hi);
  EXPECT_NEAR(hi.z(), 2.0f, 1e-6f);
  EXPECT_NEAR(hi.x(), 1.0f, 1e-6f);
  EXPECT_NEAR(std::max(std::abs(lo.y()), std::abs(hi.y())), 0.0f, 1e-6f);
}

TEST(AssimpMeshReader, ObjGroupsWithMaterialsArePartsWithTheirReflectance) {
  const auto dir = scratch_dir("assimp_obj_parts");
  write_file(dir, "two.mtl",
             "newmtl dark\nKd 0.1 0.1 0.1\n"
             "newmtl bright\nKd 0.9 0.6 0.9\n"
             "newmtl white\nKd 1 1 1\n");
  const std::string path = write_file(dir, "two.obj",
                                      "mtllib two.mtl\n"
                                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                      "v 0 0 1\nv 1 0 1\nv 1 1 1\n"
                                      "g floor\nusemtl dark\nf 1 2 3\nf 1 3 4\n"
                                      "g roof\nusemtl bright\nf 5 6 7\n"
                                      "g lamp\nusemtl white\nf 5 7 4\n");
  const mesh::TriangleMesh mesh = load_surfaces(path);
  ASSERT_EQ(mesh.triangle_count(), 4u);
  ASSERT_TRUE(mesh.has_parts());
  ASSERT_EQ(mesh.parts.size(), 3u);
  std::vector<float> reflectances;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) reflectances.push_back(mesh.reflectance(t));
  std::sort(reflectances.begin(), reflectances.end());
  EXPECT_FLOAT_EQ(reflectances[0], 0.1f);
  EXPECT_FLOAT_EQ(reflectances[1], 0.1f);
  EXPECT_FLOAT_EQ(reflectances[2], 0.8f);
  EXPECT_FLOAT_EQ(reflectances[3], 0.98f);  // clamped: nothing reflects everything
  // The triangles of one part are the floor's two.
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (std::abs(mesh.reflectance(t) - 0.1f) > 1e-6f) continue;
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(mesh.vertices[static_cast<size_t>(mesh.triangles[t][k])].z(), 0.0f);
  }
}

/// A COLLADA document holding one triangle, with the given up axis and unit.
std::string collada_triangle(const std::string& up_axis, double metres_per_unit,
                             const std::string& positions) {
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="u" meter=")" +
         std::to_string(metres_per_unit) + R"("/><up_axis>)" + up_axis + R"(</up_axis></asset>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="pa" count="9">)" +
         positions + R"(</float_array>
      <technique_common><accessor source="#pa" count="3" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n">
    <instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
)";
}

TEST(AssimpMeshReader, ColladaSaysItsUpAxisAndUnit) {
  const auto dir = scratch_dir("assimp_dae");
  // The same triangle, 1 m along x and its apex 2 m up, in a Z-up file in centimetres and
  // in a Y-up file in metres: both arrive Y up from assimp, and "auto" turns them Z up.
  const std::string z_up =
      write_file(dir, "z_up.dae", collada_triangle("Z_UP", 0.01, "0 0 0 100 0 0 0 0 200"));
  const std::string y_up =
      write_file(dir, "y_up.dae", collada_triangle("Y_UP", 1.0, "0 0 0 1 0 0 0 2 0"));
  for (const std::string& path : {z_up, y_up}) {
    for (const bool surfaces_only : {true, false}) {
      AssimpReadOptions options;
      options.surfaces_only = surfaces_only;
      const mesh::TriangleMesh mesh = read_mesh_with_assimp(path, nullptr, options);
      ASSERT_EQ(mesh.triangle_count(), 1u) << path;
      Eigen::Vector3f lo, hi;
      mesh.bounds(&lo, &hi);
      EXPECT_LT(lo.norm(), 1e-5f) << path;
      EXPECT_NEAR(hi.x(), 1.0f, 1e-5f) << path;
      EXPECT_NEAR(hi.z(), 2.0f, 1e-5f) << path;
      EXPECT_NEAR(hi.y(), 0.0f, 1e-5f) << path;
    }
  }
}

TEST(AssimpMeshReader, WrittenPlyReadsBack) {
  const auto dir = scratch_dir("assimp_ply_round_trip");
  // A corridor's shape: floor, two walls and a pillar, written as binary PLY.
  mesh::TriangleMesh scene;
  const uint32_t wall = scene.add_part("wall", 0.65f);
  scene.add_quad({0, -1.25f, 0}, {60, -1.25f, 0}, {60, 1.25f, 0}, {0, 1.25f, 0}, wall);
  scene.add_box({0, -1.25f, 0}, {60, -1.2f, 2.8f}, wall);
  scene.add_box({0, 1.2f, 0}, {60, 1.25f, 2.8f}, wall);
  scene.add_cylinder({30, 0, 0}, 0.2f, 2.8f, 12, wall);
  viewer_export::write_mesh((dir / "scene.ply").string(), scene);
  const mesh::TriangleMesh back = load_surfaces((dir / "scene.ply").string());
  EXPECT_EQ(back.triangle_count(), scene.triangle_count());
  Eigen::Vector3f lo, hi;
  back.bounds(&lo, &hi);
  EXPECT_TRUE(lo.isApprox(Eigen::Vector3f(0, -1.25f, 0)));
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(60, 1.25f, 2.8f)));
}

TEST(AssimpMeshReader, WithoutSurfacesOnlyAPointCloudStaysOne) {
  const auto dir = scratch_dir("assimp_points");
  const std::string path = write_file(dir, "points.ply",
                                      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                      "property float y\nproperty float z\nend_header\n"
                                      "0 0 0\n1 0 0\n0 1 0\n");
  const mesh::TriangleMesh cloud = read_mesh_with_assimp(path);
  EXPECT_TRUE(cloud.is_point_cloud());
  EXPECT_EQ(cloud.vertices.size(), 3u);
  EXPECT_TRUE(cloud.parts.empty());
  try {
    load_surfaces(path);
    ADD_FAILURE() << "a point cloud read as surfaces";
  } catch (const viewer_export::MeshFileError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(AssimpMeshReader, SharedSceneMeshes) {
  FEATSENSE_SHARED_FILE(house, "scenes/small_house.ply");
  FEATSENSE_SHARED_FILE(station, "scenes/gas_station_with_ground.ply");
  Eigen::Vector3f lo, hi;
  const mesh::TriangleMesh h = load_surfaces(house.string());
  EXPECT_EQ(h.triangle_count(), 147620u);  // the data's README
  h.bounds(&lo, &hi);
  EXPECT_NEAR(lo.z(), 0.0f, 0.05f);           // floor at z = 0
  EXPECT_NEAR(hi.x() - lo.x(), 19.0f, 2.0f);  // about 19 x 11 m
  EXPECT_NEAR(hi.y() - lo.y(), 11.0f, 2.0f);
  const mesh::TriangleMesh s = load_surfaces(station.string());
  EXPECT_EQ(s.triangle_count(), 4942u);
  s.bounds(&lo, &hi);
  EXPECT_NEAR(hi.x() - lo.x(), 80.0f, 1.0f);  // the 80 x 80 m ground quad
  EXPECT_NEAR(hi.y() - lo.y(), 80.0f, 1.0f);
  EXPECT_GT(hi.z(), 8.0f);  // the 9 m sign
}

void expect_load_error(const std::string& path, const std::string& fragment,
                       const AssimpReadOptions& options = surfaces()) {
  try {
    read_mesh_with_assimp(path, nullptr, options);
    ADD_FAILURE() << "no error for " << path;
  } catch (const viewer_export::MeshFileError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(AssimpMeshReader, BadInputNamesTheFile) {
  const auto dir = scratch_dir("assimp_bad");
  expect_load_error((dir / "missing.ply").string(), "no such mesh file");
  expect_load_error(write_file(dir, "empty.ply", ""), "cannot read the mesh");
  expect_load_error(write_file(dir, "garbage.obj", std::string(64, '\x01')), "");
  expect_load_error(write_file(dir, "nofaces.ply",
                               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nelement face 0\n"
                               "property list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1 0 0\n0 1 0\n"),
                    "");
  const std::string box = write_file(dir, "box.ply", kBoxPly);
  expect_load_error(box, "unit scale must be > 0", surfaces("auto", 0.0));
  expect_load_error(box, "up axis must be auto, y or z, not 'x'", surfaces("x"));
}

}  // namespace
}  // namespace featsense::test
