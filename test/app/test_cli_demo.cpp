#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/test_data.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  // By its size: GCC 12 warns of a null dereference in istreambuf_iterator at -O2.
  std::string text(static_cast<size_t>(fs::file_size(path)), '\0');
  std::ifstream(path, std::ios::binary)
      .read(text.data(), static_cast<std::streamsize>(text.size()));
  return text;
}

size_t embedded_pictures(const std::string& html) {
  const std::string data_uri = "src=\"data:image/png;base64,";
  size_t count = 0;
  for (size_t at = html.find(data_uri); at != std::string::npos; at = html.find(data_uri, at + 1))
    ++count;
  return count;
}

TEST(CliDemo, EstimatesThePosesAndScoresPathAndMesh) {
  const fs::path out = scratch_dir("cli_demo") / "estimated";
  const CommandResult r = run_featsense("demo -o " + out.string() + " --frames 8 --backend cpu");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("poses estimated by the odometry: ATE"), std::string::npos) << r.output;
  const nlohmann::json report = read_json(out / "report.json");
  ASSERT_TRUE(report.contains("odometry")) << report.dump(2);
  ASSERT_TRUE(report["eval"].contains("traj")) << report.dump(2);
  EXPECT_EQ(report["eval"]["traj"]["ape"]["count"].get<int>(), 8);
  EXPECT_LT(report["eval"]["traj"]["ape"]["rmse"].get<double>(), 0.05);
  ASSERT_TRUE(report["eval"].contains("mesh"));
  // Eight scans along a straight line: an alignment of the paths would turn the mesh about the
  // line at random, so the mesh is scored as mapped only.
  EXPECT_FALSE(report["eval"]["mesh"].contains("aligned"));
  // The plan view, cut 0.3 m above the lab's walk at 1.7 m, under its 4 m ceiling.
  EXPECT_TRUE(fs::is_regular_file(out / "topdown.png"));
  const nlohmann::json& plan = report["mesh"]["plan"];
  EXPECT_NEAR(plan["cut_high_m"].get<double>(), 2.0, 0.05) << plan.dump(2);

  // The trajectory's error over time, named where eval names its files.
  EXPECT_EQ(report["eval"]["traj"]["error_files"]["png"], "trajectory_error.png");
  EXPECT_TRUE(fs::is_regular_file(out / "trajectory_error.png"));
  EXPECT_NE(r.output.find("trajectory_error.png"), std::string::npos) << r.output;

  // report.html (the same demo: it is the slow part): one page beside report.json with the
  // pictures inside it, named in the report and the summary, written again by `report OUT`.
  EXPECT_EQ(report["html"], "report.html");
  EXPECT_NE(r.output.find("report.html"), std::string::npos) << r.output;
  const std::string html = read_text(out / "report.html");
  // The plan view, the mesh error and the trajectory error.
  EXPECT_EQ(embedded_pictures(html), 3u);
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_LT(html.size(), 10u << 20);

  fs::remove(out / "report.html");
  const CommandResult again = run_featsense("report " + out.string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(embedded_pictures(read_text(out / "report.html")), 3u);
}

TEST(CliDemo, GtPosesMapsWithTheTruth) {
  const fs::path out = scratch_dir("cli_demo") / "true";
  const CommandResult r = run_featsense(
      "demo -o " + out.string() + " --frames 4 --backend cpu --gt-poses" + " --plan-height 2.5");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("mapped with the true poses"), std::string::npos) << r.output;
  const nlohmann::json report = read_json(out / "report.json");
  EXPECT_FALSE(report.contains("odometry"));
  EXPECT_FALSE(report["eval"].contains("traj"));
  ASSERT_TRUE(report["eval"].contains("mesh"));
  EXPECT_FALSE(report["eval"]["mesh"].contains("aligned"));  // the map's frame is the truth's
  EXPECT_EQ(report["mesh"]["plan"]["cut_low_m"].get<double>(), 2.5);
}

TEST(CliDemo, WithTilesTheTileSetIsComparedWithTheTruth) {
  const fs::path out = scratch_dir("cli_demo") / "tiles";
  const CommandResult r =
      run_featsense("demo -o " + out.string() + " --frames 4 --backend cpu --gt-poses --tiles");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("triangles in 4 tiles"), std::string::npos)
      << r.output;  // a 20 m room about the origin
  EXPECT_TRUE(fs::is_regular_file(out / "tiles" / "tileset.json"));
  EXPECT_FALSE(fs::exists(out / "mesh.ply"));
  const nlohmann::json report = read_json(out / "report.json");
  ASSERT_TRUE(report["eval"].contains("mesh")) << report["eval"].dump();
  EXPECT_LT(report["eval"]["mesh"]["accuracy"]["mean_abs"].get<double>(), 0.05);
  EXPECT_GT(report["eval"]["mesh"]["completeness"]["0.10"].get<double>(), 0.5);
  EXPECT_FALSE(fs::exists(out / "mesh_error.ply")) << "the error files colour one mesh";
}

// The error made visible: the distances as CloudCompare's scalar fields, and as colours a glTF
// viewer shows, named in the report.
TEST(CliDemo, WritesTheMeshErrorAsFieldsAndColours) {
  const fs::path out = scratch_dir("cli_demo") / "error";
  const CommandResult r =
      run_featsense("demo -o " + out.string() + " --frames 4 --backend cpu --gt-poses");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json report = read_json(out / "report.json");
  const nlohmann::json& files = report["eval"]["mesh"]["error_files"];
  EXPECT_EQ(files["ply"], "mesh_error.ply") << report["eval"]["mesh"].dump(2);
  EXPECT_EQ(files["glb"], "mesh_error.glb");

  viewer_export::MeshAttributes fields;
  const mesh::TriangleMesh with_fields =
      viewer_export::read_mesh((out / "mesh_error.ply").string(), &fields);
  ASSERT_EQ(fields.scalars.size(), 2u);
  EXPECT_EQ(fields.scalars[0].name, "distance");
  EXPECT_EQ(fields.scalars[1].name, "signed_distance");
  ASSERT_EQ(fields.scalars[1].values.size(), with_fields.vertices.size());
  EXPECT_EQ(with_fields.vertices.size(), report["mesh"]["vertices"].get<size_t>());
  // |signed| is |d| or, where the nearest point is on an edge seen side on, less (its sign
  // then says nothing: the comparison gives 0).
  for (size_t i = 0; i < with_fields.vertices.size(); ++i)
    ASSERT_LE(std::abs(fields.scalars[1].values[i]), fields.scalars[0].values[i] + 1e-6f);

  viewer_export::MeshAttributes colours;
  const mesh::TriangleMesh coloured =
      viewer_export::read_mesh((out / "mesh_error.glb").string(), &colours);
  EXPECT_EQ(coloured.vertices.size(), with_fields.vertices.size());
  EXPECT_EQ(colours.colors.size(), coloured.vertices.size());
  EXPECT_NE(r.output.find("mesh_error.glb"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace featsense::test
