// featsense mesh end to end: an .h5 map and its .vdb export into meshes, the JSON figures, and
// the messages for bad input.

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <vector>

#include "common/run_command.hpp"
#include "common/test_data.hpp"
#include "featsense/mesh/mesh_simplification.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "featsense/storage/vdb_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"
#include "featsense/viewer_export/ply_mesh_io.hpp"
#include "mesh/tsdf_test_fields.hpp"

namespace featsense::test {
namespace {

const Eigen::Vector3d kCentre(0.02, -0.01, 0.03);
constexpr double kRadius = 1.0;

/// A sphere of radius 1 m at 5 cm voxels (eight chunks around the origin) as map.h5 and map.vdb.
std::filesystem::path write_sphere_map(const std::string& name) {
  const std::filesystem::path dir = scratch_dir(name);
  {
    storage::Hdf5ChunkStore store(dir / "map.h5", storage::OpenMode::kCreate,
                                  test_metadata(0.05, 0.15));
    write_field(store, Eigen::Vector3i::Constant(-30), Eigen::Vector3i::Constant(29),
                [](const Eigen::Vector3d& p) { return sphere_distance(p, kCentre, kRadius); });
    storage::export_vdb(store, dir / "map.vdb");
  }
  return dir;
}

TEST(CliMesh, MeshesH5AndVdbMaps) {
  const std::filesystem::path dir = write_sphere_map("cli_mesh");
  const std::string json = (dir / "mesh.json").string();
  CommandResult result = run_featsense("mesh " + (dir / "map.h5").string() + " -o " +
                                       (dir / "a.ply").string() + " --json " + json);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("from 8 chunks"), std::string::npos) << result.output;
  const mesh::TriangleMesh a = viewer_export::read_mesh((dir / "a.ply").string());
  ASSERT_GT(a.triangles.size(), 1000u);
  for (const Eigen::Vector3f& v : a.vertices) {
    ASSERT_LT(std::abs(sphere_distance(v.cast<double>(), kCentre, kRadius)), 0.001);
  }
  nlohmann::json figures;
  std::ifstream(json) >> figures;
  EXPECT_EQ(figures["triangles"].get<size_t>(), a.triangles.size());
  EXPECT_EQ(figures["vertices"].get<size_t>(), a.vertices.size());
  EXPECT_EQ(figures["chunks"].get<size_t>(), 8u);
  EXPECT_GT(figures["triangles_per_s"].get<double>(), 0.0);

  result = run_featsense("mesh " + (dir / "map.vdb").string() + " -o " + (dir / "b.glb").string() +
                         " --threads 1");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const mesh::TriangleMesh b = viewer_export::read_mesh((dir / "b.glb").string());
  EXPECT_EQ(b.triangles.size(), a.triangles.size());

  result = run_featsense("mesh " + (dir / "map.h5").string() + " -o " + (dir / "c.obj").string() +
                         " --bbox -2,-2,-2,2,2,0.2");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const mesh::TriangleMesh c = viewer_export::read_mesh((dir / "c.obj").string());
  EXPECT_LT(c.triangles.size(), a.triangles.size());
  for (const Eigen::Vector3f& v : c.vertices) EXPECT_LE(v.z(), 0.2f + 1e-5f);

  result = run_featsense("mesh " + (dir / "map.h5").string() + " -o " + (dir / "d.ply").string() +
                         " --clean --simplify 0.25 --check-self-intersections --json " + json);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("closed, manifold"), std::string::npos) << result.output;
  std::ifstream(json) >> figures;
  const nlohmann::json& cleanup = figures["cleanup"];
  EXPECT_TRUE(cleanup["is_closed"].get<bool>());
  EXPECT_EQ(cleanup["self_intersections"].get<size_t>(), 0u);
  EXPECT_LT(cleanup["simplification_max_error_m"].get<double>(), 0.005);
  const mesh::TriangleMesh d = viewer_export::read_mesh((dir / "d.ply").string());
  EXPECT_EQ(d.triangles.size(), cleanup["output_triangles"].get<size_t>());
  EXPECT_LT(d.triangles.size(), a.triangles.size() / 3);
}

TEST(CliMesh, WritesThePlanView) {
  const std::filesystem::path dir = write_sphere_map("cli_mesh_plan");
  const std::string json = (dir / "mesh.json").string();
  const std::string plan = (dir / "plan.png").string();
  CommandResult result =
      run_featsense("mesh " + (dir / "map.h5").string() + " -o " + (dir / "a.ply").string() +
                    " --plan " + plan + " --json " + json);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(std::filesystem::is_regular_file(plan));
  EXPECT_NE(result.output.find("plan view: " + plan), std::string::npos) << result.output;
  nlohmann::json figures;
  std::ifstream(json) >> figures;
  // A ball has no ceiling over a floor: without a path nothing is cut.
  EXPECT_TRUE(figures["plan"]["cut_low_m"].is_null()) << figures.dump(2);
  EXPECT_GT(figures["plan"]["width_px"].get<int>(), 0);

  // A path through the ball's middle: the cut follows it, --plan-height overrides that.
  const std::string tum = (dir / "path.tum").string();
  std::ofstream(tum) << "0.0 -0.5 0 0 0 0 0 1\n1.0 0.5 0 0 0 0 0 1\n";
  result = run_featsense("mesh " + (dir / "map.h5").string() + " -o " + (dir / "b.ply").string() +
                         " --plan " + plan + " --trajectory " + tum + " --json " + json);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::ifstream(json) >> figures;
  EXPECT_NEAR(figures["plan"]["cut_low_m"].get<double>(), 0.3, 1e-9);
  result = run_featsense("mesh " + (dir / "map.h5").string() + " -o " + (dir / "c.ply").string() +
                         " --plan " + plan + " --trajectory " + tum + " --plan-height -0.2" +
                         " --json " + json);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::ifstream(json) >> figures;
  EXPECT_NEAR(figures["plan"]["cut_high_m"].get<double>(), -0.2, 1e-9);
}

TEST(CliMesh, WritesATileSetBesideOrInsteadOfOneMesh) {
  const std::filesystem::path dir = write_sphere_map("cli_mesh_tiles");
  const std::string map = (dir / "map.h5").string();
  const std::string json = (dir / "tiles.json").string();
  // Tiles of one 3.2 m chunk: the sphere's eight chunks are four columns, four tiles.
  CommandResult result =
      run_featsense("mesh " + map + " --tiles " + (dir / "t").string() + " --tile-size 3 -o " +
                    (dir / "one.ply").string() + " --json " + json);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("4 tiles of 3.2 m"), std::string::npos) << result.output;
  nlohmann::json figures;
  std::ifstream(json) >> figures;
  const nlohmann::json& tiles = figures["tiles"];
  EXPECT_EQ(tiles["tiles"].get<size_t>(), 4u);
  EXPECT_EQ(tiles["triangles"].get<size_t>(), figures["triangles"].get<size_t>());
  EXPECT_EQ(tiles["levels"].size(), 2u);
  EXPECT_GT(tiles["peak_rss_mb"].get<double>(), 0.0);
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "t" / "tileset.json"));
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "t" / "tiles" / "0" / "-1_-1.ply"));

  // Cleaned tile by tile, the cuts held: the four quarters still weld into a closed ball.
  result = run_featsense("mesh " + map + " --tiles " + (dir / "c").string() +
                         " --tile-size 3 --clean --json " + json);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::ifstream(json) >> figures;
  const nlohmann::json& cleanup = figures["tiles"]["cleanup"];
  EXPECT_EQ(cleanup["holes_filled"], 0) << cleanup;
  EXPECT_EQ(cleanup["borders_on_cuts"], 4) << cleanup;
  std::vector<mesh::TriangleMesh> quarters;
  for (const char* name : {"-1_-1", "-1_0", "0_-1", "0_0"})
    quarters.push_back(viewer_export::read_mesh(
        (dir / "c" / "tiles" / "0" / (std::string(name) + ".ply")).string()));
  std::vector<const mesh::TriangleMesh*> parts;
  for (const mesh::TriangleMesh& q : quarters) parts.push_back(&q);
  const mesh::TriangleMesh ball = mesh::weld_by_position(parts);
  std::map<std::pair<int, int>, int> edge_uses;
  for (const Eigen::Vector3i& t : ball.triangles)
    for (int k = 0; k < 3; ++k)
      ++edge_uses[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  size_t border = 0;
  for (const auto& [edge, uses] : edge_uses) border += uses == 1 ? 1 : 0;
  EXPECT_EQ(border, 0u) << "the cleaned tiles do not meet";

  // Tiles alone, quietly, GLB only.
  result = run_featsense("--quiet mesh " + map + " --tiles " + (dir / "q").string() +
                         " --tile-size 3 --no-tile-ply");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, "");
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "q" / "tiles" / "0" / "0_0.glb"));
  EXPECT_FALSE(std::filesystem::exists(dir / "q" / "tiles" / "0" / "0_0.ply"));

  // A tile set is compared with a reference as the one mesh is (its tiles read a few at a
  // time, their shared vertices once), from PLY or GLB tiles. The reference: one quarter.
  const std::string reference = (dir / "t" / "tiles" / "0" / "-1_-1.ply").string();
  auto eval = [&](const std::string& estimate) {
    const CommandResult run =
        run_featsense("eval mesh " + estimate + " " + reference + " --json -");
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return nlohmann::json::parse(run.output.substr(run.output.find('{')));
  };
  const nlohmann::json one = eval((dir / "one.ply").string());
  EXPECT_GT(one["accuracy"]["max"].get<double>(), 0.5) << "the other quarters are far off";
  for (const char* set : {"t", "q"}) {
    const nlohmann::json tiled = eval((dir / set).string());
    EXPECT_EQ(tiled["points"], one["points"]) << set;
    EXPECT_NEAR(tiled["accuracy"]["mean_abs"].get<double>(),
                one["accuracy"]["mean_abs"].get<double>(), 1e-9)
        << set;
    EXPECT_EQ(tiled["accuracy"]["max"], one["accuracy"]["max"]) << set;
    EXPECT_EQ(tiled["completeness"], one["completeness"]) << set;
  }
  result = run_featsense("eval mesh " + (dir / "t").string() + " " + reference + " --ply-out " +
                         (dir / "e.ply").string());
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("is a tile set"), std::string::npos) << result.output;

  // Navigation layers a tile at a time (with its neighbours) are the whole mesh's, vertex for
  // vertex, on the cuts too. A steep limit so that the sphere has lethal and free parts.
  const std::string limits = " --max-slope-deg 40 --radius 0.2";
  result = run_featsense("navmesh " + (dir / "one.ply").string() + " -o " +
                         (dir / "nav_one.ply").string() + limits);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  result =
      run_featsense("navmesh " + (dir / "t").string() + " -o " + (dir / "nav").string() + limits);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("4 tiles"), std::string::npos) << result.output;
  using Key = std::array<float, 3>;
  auto layers_by_position = [](const std::filesystem::path& file) {
    viewer_export::MeshAttributes attributes;
    const mesh::TriangleMesh m = viewer_export::read_ply_mesh(file.string(), &attributes);
    std::map<Key, std::vector<float>> out;
    for (size_t v = 0; v < m.vertices.size(); ++v) {
      std::vector<float>& values = out[{m.vertices[v].x(), m.vertices[v].y(), m.vertices[v].z()}];
      for (const viewer_export::VertexScalar& layer : attributes.scalars)
        values.push_back(layer.values[v]);
    }
    return out;
  };
  const std::map<Key, std::vector<float>> whole = layers_by_position(dir / "nav_one.ply");
  size_t compared = 0;
  size_t lethal = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "nav")) {
    if (entry.path().extension() != ".ply") continue;
    for (const auto& [position, values] : layers_by_position(entry.path())) {
      const auto found = whole.find(position);
      ASSERT_NE(found, whole.end()) << "a tile's vertex is not in the whole mesh";
      ASSERT_EQ(values.size(), found->second.size());
      for (size_t k = 0; k < values.size(); ++k) EXPECT_NEAR(values[k], found->second[k], 1e-4);
      lethal += values.back() > 0.5f ? 1 : 0;
      ++compared;
    }
  }
  EXPECT_GE(compared, whole.size());  // the cuts' vertices in two tiles
  EXPECT_GT(lethal, 0u);
  EXPECT_LT(lethal, compared);
  // The same from GLB tiles alone, whose copies of a cut's vertex come back a float rounding
  // apart: welded all the same, the cuts' layers are the whole mesh's too.
  result =
      run_featsense("navmesh " + (dir / "q").string() + " -o " + (dir / "nav_q").string() + limits);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  std::map<std::array<long, 3>, std::vector<std::pair<Key, const std::vector<float>*>>> grid;
  const auto cell_of = [](const Key& p, int dx, int dy, int dz) {
    return std::array<long, 3>{std::lround(std::floor(p[0] * 1000.0f)) + dx,
                               std::lround(std::floor(p[1] * 1000.0f)) + dy,
                               std::lround(std::floor(p[2] * 1000.0f)) + dz};
  };
  for (const auto& [position, values] : whole)
    grid[cell_of(position, 0, 0, 0)].push_back({position, &values});
  size_t compared_glb = 0;
  double worst_deg = 0.0;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "nav_q")) {
    if (entry.path().extension() != ".ply") continue;
    for (const auto& [position, values] : layers_by_position(entry.path())) {
      const std::vector<float>* nearest = nullptr;
      double nearest_m = 1e-4;  // within 0.1 mm of a vertex of the whole mesh
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const auto found = grid.find(cell_of(position, dx, dy, dz));
            if (found == grid.end()) continue;
            for (const auto& [p, v] : found->second) {
              const double d =
                  std::hypot(p[0] - position[0], p[1] - position[1], p[2] - position[2]);
              if (d < nearest_m) {
                nearest_m = d;
                nearest = v;
              }
            }
          }
      ASSERT_NE(nearest, nullptr) << "a GLB tile's vertex is not in the whole mesh";
      ASSERT_EQ(values.size(), nearest->size());
      for (size_t k = 0; k + 1 < values.size(); ++k)
        worst_deg = std::max(worst_deg, static_cast<double>(std::abs(values[k] - (*nearest)[k])));
      EXPECT_EQ(values.back(), nearest->back()) << "lethal";
      ++compared_glb;
    }
  }
  EXPECT_EQ(compared_glb, compared);
  EXPECT_LT(worst_deg, 1e-2);
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "nav" / "navmesh.json"));
  EXPECT_FALSE(std::filesystem::exists(dir / "nav" / ".margins")) << "the tiles' parts are left";
  result = run_featsense("navmesh " + (dir / "t").string() + " -o " + (dir / "nav.ply").string());
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("-o names a folder"), std::string::npos) << result.output;
  // A folder whose name holds a dot is a folder all the same.
  result = run_featsense("navmesh " + (dir / "t").string() + " -o " + (dir / "nav_2.5").string());
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(std::filesystem::is_regular_file(dir / "nav_2.5" / "navmesh.json"));
}

TEST(CliMesh, ErrorsAreClear) {
  const std::filesystem::path dir = write_sphere_map("cli_mesh_errors");
  const std::string map = (dir / "map.h5").string();
  const std::string out = " -o " + (dir / "out.ply").string();
  struct Case {
    std::string args;
    std::string message;
  };
  const std::string missing = (dir / "missing.h5").string();
  const std::string foreign = (dir / "foreign.h5").string();
  std::ofstream(foreign) << "not a map\n";
  const std::string text = (dir / "notes.txt").string();
  std::ofstream(text) << "not a map either\n";
  const std::vector<Case> cases = {
      {"mesh " + missing + out, missing + ": no such map file"},
      {"mesh " + foreign + out, foreign},
      {"mesh " + text + out, "not a featsense map"},
      {"mesh " + map + out + " --bbox 1,2,3", "--bbox: expected"},
      {"mesh " + map + out + " --bbox 0,0,0,1,1,a", "--bbox: expected"},
      {"mesh " + map + out + " --bbox 1,0,0,0,1,1", "minimum must be below"},
      {"mesh " + map + out + " --min-weight -1",
       "--min-weight: must be a number of measurements >= 0"},
      {"mesh " + map + out + " --threads -2", "--threads: must be >= 0"},
      {"mesh " + map + out + " --simplify 0",
       "--simplify: the fraction of triangles to keep must be in (0, 1]"},
      {"mesh " + map + out + " --simplify 1.5", "--simplify: the fraction"},
      {"mesh " + map + " -o " + (dir / "out.stl").string(), "unknown mesh format '.stl'"},
      {"mesh " + map + out + " --bbox 10,10,10,11,11,11", "no surface to mesh inside --bbox"},
      {"mesh " + map + out + " --plan-height 1", "--plan-height goes with --plan"},
      {"mesh " + map + out + " --plan " + (dir / "plan.jpg").string(), "the plan view is a PNG"},
      {"mesh " + map, "give -o MESH (one mesh), --tiles DIR (a tile set), or both"},
      {"mesh " + map + " --tiles " + (dir / "t").string() + " --tile-size 0",
       "--tile-size: must be a positive number of metres"},
      {"mesh " + map + " --tiles " + (dir / "t").string() + " --simplify 0.5", "work on one mesh"},
  };
  for (const Case& c : cases) {
    const CommandResult result = run_featsense(c.args);
    EXPECT_NE(result.exit_code, 0) << c.args;
    EXPECT_NE(result.output.find(c.message), std::string::npos) << c.args << "\n" << result.output;
  }
}

TEST(CliBenchMesh, PrintsTheFigures) {
  const std::filesystem::path dir = scratch_dir("cli_bench_mesh");
  const std::string json = (dir / "bench.json").string();
  const CommandResult result =
      run_featsense("bench mesh --map 10x10x4 --repeat 2 --threads 1 --json " + json);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  nlohmann::json figures;
  std::ifstream(json) >> figures;
  for (const char* key : {"median_ms", "p95_ms", "max_ms", "voxels", "triangles", "voxels_per_s",
                          "triangles_per_s", "threads"}) {
    EXPECT_TRUE(figures.contains(key)) << key;
  }
  EXPECT_EQ(figures["threads"].get<int>(), 1);
  EXPECT_GT(figures["triangles"].get<size_t>(), 10000u);
  EXPECT_GT(figures["triangles_per_s"].get<double>(), 0.0);
}

}  // namespace
}  // namespace featsense::test
