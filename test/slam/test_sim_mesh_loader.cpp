// Scene meshes from files: PLY and OBJ written here, the shared real scenes, bad input.

#include <gtest/gtest.h>

#include <fstream>

#include "common/test_data.hpp"
#include "featsense/slam/scan_source.hpp"
#include "featsense/slam/sim/mesh_loader.hpp"
#include "featsense/slam/sim/scene_library.hpp"
#include "featsense/slam/sim/simulation_writer.hpp"

namespace featsense::slam {
namespace {

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

TEST(SimMeshLoader, ReadsAPlyBoxWithItsSize) {
  const auto dir = test::scratch_dir("sim_mesh_ply");
  const mesh::TriangleMesh mesh = load_mesh(write_file(dir, "box.ply", kBoxPly));
  EXPECT_EQ(mesh.triangle_count(), 12u);
  Eigen::Vector3f lo, hi;
  mesh.bounds(&lo, &hi);
  EXPECT_TRUE(lo.isApprox(Eigen::Vector3f(0, 0, 0)));
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(2, 3, 4)));
  ASSERT_EQ(mesh.triangle_part.size(), 12u);
  EXPECT_FLOAT_EQ(mesh.reflectance(0), mesh.parts[mesh.triangle_part[0]].reflectance);
}

TEST(SimMeshLoader, ObjWithUnitScaleAndUpAxis) {
  const auto dir = test::scratch_dir("sim_mesh_obj");
  // One triangle in centimetres, its apex 200 cm along the file's y axis.
  const std::string obj = "v 0 0 0\nv 100 0 0\nv 0 200 0\nf 1 2 3\n";
  const std::string path = write_file(dir, "tri.obj", obj);
  MeshLoadOptions options;
  options.unit_scale = 0.01;
  options.up_axis = "z";
  mesh::TriangleMesh mesh = load_mesh(path, options);
  ASSERT_EQ(mesh.triangle_count(), 1u);
  Eigen::Vector3f lo, hi;
  mesh.bounds(&lo, &hi);
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(1, 2, 0)));
  options.up_axis = "y";  // the file's y is up: it becomes z
  mesh = load_mesh(path, options);
  mesh.bounds(&lo, &hi);
  EXPECT_NEAR(hi.z(), 2.0f, 1e-6f);
  EXPECT_NEAR(hi.x(), 1.0f, 1e-6f);
  EXPECT_NEAR(std::max(std::abs(lo.y()), std::abs(hi.y())), 0.0f, 1e-6f);
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

TEST(SimMeshLoader, ColladaSaysItsUpAxisAndUnit) {
  const auto dir = test::scratch_dir("sim_mesh_dae");
  // The same triangle, 1 m along x and its apex 2 m up, in a Z-up file in centimetres and
  // in a Y-up file in metres.
  const std::string z_up =
      write_file(dir, "z_up.dae", collada_triangle("Z_UP", 0.01, "0 0 0 100 0 0 0 0 200"));
  const std::string y_up =
      write_file(dir, "y_up.dae", collada_triangle("Y_UP", 1.0, "0 0 0 1 0 0 0 2 0"));
  for (const std::string& path : {z_up, y_up}) {
    const mesh::TriangleMesh mesh = load_mesh(path);
    ASSERT_EQ(mesh.triangle_count(), 1u) << path;
    Eigen::Vector3f lo, hi;
    mesh.bounds(&lo, &hi);
    EXPECT_LT(lo.norm(), 1e-5f) << path;
    EXPECT_NEAR(hi.x(), 1.0f, 1e-5f) << path;
    EXPECT_NEAR(hi.z(), 2.0f, 1e-5f) << path;
    EXPECT_NEAR(hi.y(), 0.0f, 1e-5f) << path;
  }
}

TEST(SimMeshLoader, WrittenGroundTruthMeshReadsBack) {
  const auto dir = test::scratch_dir("sim_mesh_roundtrip");
  const mesh::TriangleMesh scene = build_scene("corridor");
  write_mesh_ply(scene, (dir / "scene.ply").string());
  const mesh::TriangleMesh back = load_mesh((dir / "scene.ply").string());
  EXPECT_EQ(back.triangle_count(), scene.triangle_count());
  Eigen::Vector3f lo, hi;
  back.bounds(&lo, &hi);
  EXPECT_TRUE(lo.isApprox(Eigen::Vector3f(0, -1.25f, 0)));
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(60, 1.25f, 2.8f)));
}

TEST(SimMeshLoader, SharedSceneMeshes) {
  FEATSENSE_SHARED_FILE(house, "scenes/small_house.ply");
  FEATSENSE_SHARED_FILE(station, "scenes/gas_station_with_ground.ply");
  Eigen::Vector3f lo, hi;
  const mesh::TriangleMesh h = load_mesh(house.string());
  EXPECT_EQ(h.triangle_count(), 147620u);  // the data's README
  h.bounds(&lo, &hi);
  EXPECT_NEAR(lo.z(), 0.0f, 0.05f);           // floor at z = 0
  EXPECT_NEAR(hi.x() - lo.x(), 19.0f, 2.0f);  // about 19 x 11 m
  EXPECT_NEAR(hi.y() - lo.y(), 11.0f, 2.0f);
  const mesh::TriangleMesh s = load_mesh(station.string());
  EXPECT_EQ(s.triangle_count(), 4942u);
  s.bounds(&lo, &hi);
  EXPECT_NEAR(hi.x() - lo.x(), 80.0f, 1.0f);  // the 80 x 80 m ground quad
  EXPECT_NEAR(hi.y() - lo.y(), 80.0f, 1.0f);
  EXPECT_GT(hi.z(), 8.0f);  // the 9 m sign
}

void expect_load_error(const std::string& path, const std::string& fragment) {
  try {
    load_mesh(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(SimMeshLoader, BadInputNamesTheFile) {
  const auto dir = test::scratch_dir("sim_mesh_bad");
  expect_load_error((dir / "missing.ply").string(), "no such mesh file");
  expect_load_error(write_file(dir, "empty.ply", ""), "cannot read the mesh");
  expect_load_error(write_file(dir, "garbage.obj", std::string(64, '\x01')), "");
  expect_load_error(write_file(dir, "nofaces.ply",
                               "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nelement face 0\n"
                               "property list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1 0 0\n0 1 0\n"),
                    "");
}

}  // namespace
}  // namespace featsense::slam
