// featsense export and navmesh end to end: formats by extension, layers in the output, errors.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "common/run_command.hpp"
#include "common/test_data.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"
#include "mesh/mesh_test_shapes.hpp"

namespace featsense::test {
namespace {

/// A 2 m x 2 m ramp rising along x at `slope_deg`, as a PLY without normals.
std::string write_ramp(const std::filesystem::path& dir, double slope_deg) {
  mesh::TriangleMesh ramp = grid_plane(-1, 1, -1, 1, 0, 20);
  const auto gradient = static_cast<float>(std::tan(slope_deg * 3.14159265358979323846 / 180.0));
  for (Eigen::Vector3f& v : ramp.vertices) v.z() = gradient * v.x();
  const std::string path = (dir / "ramp.ply").string();
  viewer_export::write_ply_mesh(path, ramp);
  return path;
}

std::string head_of(const std::string& path, size_t bytes) {
  std::ifstream in(path, std::ios::binary);
  std::string text(bytes, '\0');
  in.read(text.data(), static_cast<std::streamsize>(bytes));
  text.resize(static_cast<size_t>(in.gcount()));
  return text;
}

TEST(CliExport, WritesEveryFormatAndReadsItBack) {
  const std::filesystem::path dir = scratch_dir("cli_export");
  const std::string ramp = write_ramp(dir, 10.0);
  const mesh::TriangleMesh original = viewer_export::read_mesh(ramp);
  for (const std::string name : {"out.ply", "out.obj", "out.glb", "out.gltf"}) {
    const std::string out = (dir / name).string();
    const CommandResult result = run_featsense("export " + ramp + " -o " + out);
    ASSERT_EQ(result.exit_code, 0) << result.output;
    const mesh::TriangleMesh read = viewer_export::read_mesh(out);
    ASSERT_EQ(read.vertices.size(), original.vertices.size()) << name;
    EXPECT_EQ(read.triangles, original.triangles) << name;
    for (size_t i = 0; i < read.vertices.size(); ++i) {
      EXPECT_LT((read.vertices[i] - original.vertices[i]).norm(), 1e-5f) << name << " " << i;
    }
  }
  const CommandResult ascii =
      run_featsense("export " + ramp + " --ascii -o " + (dir / "ascii.ply").string());
  ASSERT_EQ(ascii.exit_code, 0) << ascii.output;
  EXPECT_NE(head_of((dir / "ascii.ply").string(), 64).find("format ascii 1.0"), std::string::npos);
  ASSERT_EQ(run_featsense("export " + ramp + " -o " + (dir / "nav.h5").string()).exit_code, 0);
  EXPECT_EQ(head_of((dir / "nav.h5").string(), 4), "\x89HDF");
}

TEST(CliExport, ErrorsAreClear) {
  const std::filesystem::path dir = scratch_dir("cli_export_errors");
  const std::string ramp = write_ramp(dir, 10.0);
  CommandResult result = run_featsense("export " + ramp + " -o " + (dir / "out.stl").string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("unknown mesh format '.stl'"), std::string::npos) << result.output;
  const std::string unwritable = (dir / "missing" / "out.glb").string();
  result = run_featsense("export " + ramp + " -o " + unwritable);
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find(unwritable), std::string::npos) << result.output;
  const std::string empty = (dir / "empty.ply").string();
  std::ofstream(empty) << "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n";
  result = run_featsense("navmesh " + empty + " -o " + (dir / "nav.ply").string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("no vertices"), std::string::npos) << result.output;
  result = run_featsense("export " + empty + " -o " + (dir / "e.glb").string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("empty"), std::string::npos) << result.output;
}

TEST(CliNavmesh, LayersAndLethalFaces) {
  const std::filesystem::path dir = scratch_dir("cli_navmesh");
  for (const double slope_deg : {10.0, 30.0}) {
    const std::string ramp = write_ramp(dir, slope_deg);
    const std::string out = (dir / "nav.ply").string();
    const CommandResult result = run_featsense("navmesh " + ramp + " -o " + out +
                                               " --max-slope-deg 20 --max-step 10 --radius 0.3");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    // 20 x 20 cells of two triangles: none or all beyond the 20 deg limit.
    EXPECT_NE(result.output.find(slope_deg < 20 ? ", 0 lethal" : ", 800 lethal"), std::string::npos)
        << result.output;
    const std::string header = head_of(out, 800);
    for (const std::string layer :
         {"inclination_deg", "roughness_deg", "height_diff_m", "cost", "lethal"}) {
      EXPECT_NE(header.find("property float scalar_" + layer + "\n"), std::string::npos) << layer;
    }
    EXPECT_NE(header.find("property uchar red"), std::string::npos);
    viewer_export::MeshAttributes layers;
    viewer_export::read_mesh(out, &layers);
    ASSERT_EQ(layers.scalars.size(), 5u);
    ASSERT_EQ(layers.scalars[0].name, "inclination_deg");
    for (const float inclination : layers.scalars[0].values) {
      EXPECT_NEAR(inclination, slope_deg, 2e-3);
    }
  }
  const std::string ramp = (dir / "ramp.ply").string();
  for (const std::string name : {"nav.glb", "nav.h5"}) {
    const CommandResult result = run_featsense("navmesh " + ramp + " -o " + (dir / name).string());
    EXPECT_EQ(result.exit_code, 0) << result.output;
  }
}

}  // namespace
}  // namespace featsense::test
