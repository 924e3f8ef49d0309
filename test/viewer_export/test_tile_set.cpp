// The tile set of a map: tileset.json keeps 3D Tiles 1.1's rules (asset version, boxes that hold
// their children and content, geometric errors falling to 0 at the full-resolution tiles,
// content that exists), the full-resolution tiles hold the whole map's mesh, parents fewer
// triangles than their children, the index lists the tiles, the GLBs pass the Khronos
// validator, the set passes test/tools/check_tileset.mjs (which finds each rule broken on
// purpose), and the files are the same whatever the threads.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <stdexcept>
#include <utility>

#include <nlohmann/json.hpp>

#include "common/file_bytes.hpp"
#include "common/gltf_validator.hpp"
#include "common/test_data.hpp"
#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"
#include "featsense/viewer_export/tile_set.hpp"
#include "mesh/map_tile_scene.hpp"

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

Eigen::AlignedBox3d box_of(const nlohmann::json& tile) {
  const nlohmann::json& b = tile["boundingVolume"]["box"];
  EXPECT_EQ(b.size(), 12u);
  const Eigen::Vector3d centre(b[0], b[1], b[2]);
  // Axis-aligned: the half-axes along x, y and z.
  EXPECT_EQ(b[4].get<double>(), 0.0);
  EXPECT_EQ(b[8].get<double>(), 0.0);
  const Eigen::Vector3d half(b[3], b[7], b[11]);
  EXPECT_GT(half.minCoeff(), 0.0) << "a box without volume";
  return {centre - half, centre + half};
}

struct Walk {
  fs::path dir;
  size_t leaf_triangles = 0;
  size_t leaves = 0;
  int deepest = 0;
};

/// Checks a tile and its children; returns the triangles of its content.
size_t check_tile(const nlohmann::json& tile, const Eigen::AlignedBox3d& parent_box,
                  double parent_error, int depth, Walk& walk) {
  const Eigen::AlignedBox3d box = box_of(tile);
  const double error = tile["geometricError"].get<double>();
  EXPECT_GE(error, 0.0);
  EXPECT_LE(error, parent_error);
  EXPECT_TRUE(parent_box.contains(box.min()) && parent_box.contains(box.max()))
      << "a child's box reaches outside its parent's";
  EXPECT_EQ(tile["refine"], "REPLACE");
  const std::string uri = tile["content"]["uri"];
  const fs::path content = walk.dir / uri;
  EXPECT_TRUE(fs::is_regular_file(content)) << uri;
  const mesh::TriangleMesh m = viewer_export::read_mesh(content.string());
  const Eigen::AlignedBox3d grown(box.min().array() - 1e-3, box.max().array() + 1e-3);
  for (const Eigen::Vector3f& v : m.vertices) {
    EXPECT_TRUE(grown.contains(v.cast<double>())) << uri << ": vertex outside the tile's box";
    if (!grown.contains(v.cast<double>())) break;
  }
  walk.deepest = std::max(walk.deepest, depth);
  if (!tile.contains("children")) {
    EXPECT_EQ(error, 0.0) << "full resolution has no error";
    walk.leaf_triangles += m.triangles.size();
    ++walk.leaves;
    return m.triangles.size();
  }
  EXPECT_GT(error, 0.0);
  size_t children_triangles = 0;
  for (const nlohmann::json& child : tile["children"])
    children_triangles += check_tile(child, box, error, depth + 1, walk);
  EXPECT_LT(m.triangles.size(), children_triangles) << uri << " is not coarser than its children";
  return m.triangles.size();
}

TEST(TileSet, TilesetKeepsTheRulesAndTheTilesHoldTheWholeMesh) {
  storage::MemoryChunkStore store = tile_scene_store();
  const size_t whole = mesh::extract_mesh(store, {}).triangles.size();
  const fs::path dir = scratch_dir("tile_set");
  viewer_export::TileSetSettings settings;
  settings.tile_size_m = 3.0;  // one chunk of 3.2 m: 4 x 4 tiles, three levels
  size_t progress_calls = 0;
  settings.progress = [&](size_t done, size_t total) {
    ++progress_calls;
    EXPECT_LE(done, total);
  };
  const viewer_export::TileSetReport report =
      viewer_export::write_tile_set(store, dir.string(), settings);
  EXPECT_EQ(report.tiles, 16u);
  EXPECT_EQ(progress_calls, 16u);
  EXPECT_EQ(report.triangles, whole);
  EXPECT_NEAR(report.tile_size_m, 3.2, 1e-9);
  ASSERT_EQ(report.levels.size(), 3u);
  EXPECT_EQ(report.levels[2].tiles, 1u);
  EXPECT_LT(report.levels[1].triangles, report.levels[0].triangles);

  nlohmann::json tileset;
  std::ifstream(dir / "tileset.json") >> tileset;
  EXPECT_EQ(tileset["asset"]["version"], "1.1");
  const nlohmann::json& root = tileset["root"];
  const Eigen::AlignedBox3d everything(Eigen::Vector3d::Constant(-1e9),
                                       Eigen::Vector3d::Constant(1e9));
  Walk walk{dir};
  check_tile(root, everything, tileset["geometricError"].get<double>(), 0, walk);
  EXPECT_EQ(walk.leaves, 16u);
  EXPECT_EQ(walk.leaf_triangles, whole);
  EXPECT_EQ(walk.deepest, 2);

  nlohmann::json index;
  std::ifstream(dir / "tiles.json") >> index;
  ASSERT_EQ(index["tiles"].size(), 16u);
  size_t indexed = 0;
  for (const nlohmann::json& tile : index["tiles"]) {
    indexed += tile["triangles"].get<size_t>();
    EXPECT_TRUE(fs::is_regular_file(dir / tile["ply"].get<std::string>()));
    EXPECT_EQ(
        viewer_export::read_mesh((dir / tile["ply"].get<std::string>()).string()).triangles.size(),
        tile["triangles"].get<size_t>());
  }
  EXPECT_EQ(indexed, whole);

  expect_valid((dir / root["content"]["uri"].get<std::string>()).string());
  expect_valid((dir / "tiles/0/0_0.glb").string());
}

/// Runs test/tools/check_tileset.mjs on dir/tileset.json (with the Khronos validator on the
/// GLBs where `gltf`): its exit status and its report.
std::pair<int, nlohmann::json> check_tileset(const fs::path& dir, bool gltf = true) {
  const ValidatorRun run = run_tileset_check((dir / "tileset.json").string(), gltf);
  nlohmann::json report;
  try {
    report = nlohmann::json::parse(run.output);
  } catch (const nlohmann::json::exception&) {
    ADD_FAILURE() << "check_tileset.mjs did not print one JSON line: " << run.output;
  }
  return {run.status, report};
}

void rewrite_tileset(const fs::path& dir, const std::function<void(nlohmann::json&)>& change) {
  nlohmann::json tileset;
  std::ifstream(dir / "tileset.json") >> tileset;
  change(tileset);
  std::ofstream(dir / "tileset.json") << tileset.dump(1);
}

TEST(TileSet, TheTilesetCheckerPassesTheSetAndFindsEachBrokenRule) {
  // The 3D Tiles rules a streaming viewer relies on, checked on the files by a program of their
  // own (test/tools/check_tileset.mjs, the Khronos validator on every GLB), the same that
  // checks the large tile sets of the benchmarks; each rule broken on purpose is found.
  if (!validator_present())
    GTEST_SKIP() << "node or gltf-validator missing (npm install in test/tools)";
  storage::MemoryChunkStore store = tile_scene_store();
  const fs::path dir = scratch_dir("tile_set_checked");
  viewer_export::TileSetSettings settings;
  settings.tile_size_m = 3.0;
  settings.write_ply = false;
  viewer_export::write_tile_set(store, dir.string(), settings);
  const auto [status, report] = check_tileset(dir);
  EXPECT_EQ(status, 0) << report.dump(1);
  EXPECT_EQ(report["tiles"], 21);  // 16 + 4 + 1
  EXPECT_EQ(report["contents"], 21);
  EXPECT_EQ(report["gltf_validated"], 21);
  EXPECT_EQ(report["error_count"], 0) << report.dump(1);
  const std::string original = file_bytes(dir / "tileset.json");

  const auto expect_found = [&](const std::string& what, const std::string& words) {
    const auto [broken_status, broken] = check_tileset(dir, false);  // the rules alone
    EXPECT_EQ(broken_status, 1) << what;
    EXPECT_NE(broken.dump().find(words), std::string::npos) << what << ": " << broken.dump(1);
    std::ofstream(dir / "tileset.json") << original;
  };
  rewrite_tileset(dir, [](nlohmann::json& t) {
    t["root"]["children"][0]["geometricError"] = t["root"]["geometricError"].get<double>() + 1.0;
  });
  expect_found("a child coarser than its parent", "above its parent's");
  rewrite_tileset(dir, [](nlohmann::json& t) {
    t["root"]["children"][1]["children"][2]["boundingVolume"]["box"][0] = 100.0;
  });
  expect_found("a tile moved away from its content", "reaches outside");
  rewrite_tileset(dir, [](nlohmann::json& t) { t["root"].erase("refine"); });
  expect_found("a root without refine", "the root has no refine");
  rewrite_tileset(dir, [](nlohmann::json& t) { t["root"]["boundingVolume"]["box"].erase(11); });
  expect_found("a box of 11 numbers", "box is not 12 finite numbers");
  const std::string leaf = "tiles/0/0_0.glb";
  const std::string glb = file_bytes(dir / leaf);
  fs::remove(dir / leaf);
  expect_found("a missing content", "does not exist");
  std::ofstream(dir / leaf, std::ios::binary) << glb.substr(0, glb.size() / 2);
  expect_found("a truncated GLB", "GLB length");
}

TEST(TileSet, LevelsAreAddedAboveTheRootUntilItIsSmallEnough) {
  storage::MemoryChunkStore store = tile_scene_store();
  const fs::path dir = scratch_dir("tile_set_small_root");
  viewer_export::TileSetSettings settings;
  settings.tile_size_m = 3.0;
  settings.write_ply = false;
  settings.root_triangles = 1000;
  const viewer_export::TileSetReport report =
      viewer_export::write_tile_set(store, dir.string(), settings);
  ASSERT_GT(report.levels.size(), 3u) << "the quadtree alone has three levels";
  EXPECT_EQ(report.levels.back().tiles, 1u);
  EXPECT_LE(report.root.triangles, 1000u);
  EXPECT_EQ(report.root.level + 1, static_cast<int>(report.levels.size()));
  nlohmann::json tileset;
  std::ifstream(dir / "tileset.json") >> tileset;
  Walk walk{dir};
  check_tile(tileset["root"],
             Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1e9), Eigen::Vector3d::Constant(1e9)),
             tileset["geometricError"].get<double>(), 0, walk);
  EXPECT_EQ(walk.leaves, 16u);
  EXPECT_EQ(walk.deepest, report.root.level);
}

TEST(TileSet, TheOverviewIsTheFinestLevelWithinItsBudget) {
  storage::MemoryChunkStore store = tile_scene_store();
  const size_t whole = mesh::extract_mesh(store, {}).triangles.size();
  viewer_export::TileSetSettings settings;
  settings.tile_size_m = 3.0;
  settings.write_ply = false;
  settings.overview_triangles = whole;
  viewer_export::TileSetReport report =
      viewer_export::write_tile_set(store, scratch_dir("overview_a").string(), settings);
  EXPECT_EQ(report.overview_level, 0);
  EXPECT_EQ(report.overview.triangles.size(), whole);

  settings.overview_triangles = report.levels[1].triangles;
  report = viewer_export::write_tile_set(store, scratch_dir("overview_b").string(), settings);
  EXPECT_EQ(report.overview_level, 1);
  EXPECT_EQ(report.overview.triangles.size(), report.levels[1].triangles);

  settings.overview_triangles = 10;
  report = viewer_export::write_tile_set(store, scratch_dir("overview_c").string(), settings);
  EXPECT_EQ(report.overview_level, -1);
  EXPECT_TRUE(report.overview.triangles.empty());
}

/// Every file under `dir`, by its path below it, with its bytes.
std::map<std::string, std::string> files_of(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    files[fs::relative(entry.path(), dir).string()] = file_bytes(entry.path());
  }
  return files;
}

TEST(TileSet, TheFilesAndTheOverviewDoNotDependOnTheThreads) {
  // The nodes' cleanup, levels and files run as tasks beside the meshing: in any order, the
  // same set.
  storage::MemoryChunkStore store = tile_scene_store();
  viewer_export::TileSetSettings settings;
  settings.tile_size_m = 3.0;
  settings.cleanup.emplace();
  settings.overview_triangles = mesh::extract_mesh(store, {}).triangles.size();
  const fs::path one_dir = scratch_dir("threads_one");
  const fs::path all_dir = scratch_dir("threads_all");
  viewer_export::TileSetReport one_thread;
  {
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    one_thread = viewer_export::write_tile_set(store, one_dir.string(), settings);
  }
  settings.tiles_in_work = 8;  // as many tiles finished at once as there are tiles
  const viewer_export::TileSetReport all =
      viewer_export::write_tile_set(store, all_dir.string(), settings);
  const auto expected = files_of(one_dir);
  const auto files = files_of(all_dir);
  ASSERT_EQ(files.size(), expected.size());
  EXPECT_GT(files.size(), 16u);
  for (const auto& [path, bytes] : expected) {
    ASSERT_TRUE(files.count(path)) << path;
    EXPECT_TRUE(files.at(path) == bytes) << path;
  }
  EXPECT_EQ(all.triangles, one_thread.triangles);
  EXPECT_EQ(all.cleanup->output_triangles, one_thread.cleanup->output_triangles);
  EXPECT_EQ(all.overview.vertices, one_thread.overview.vertices);
  EXPECT_EQ(all.overview.triangles, one_thread.overview.triangles);
}

TEST(TileSet, OneTileIsItsOwnRootAndBadInputIsRefused) {
  // Tiles start at the map's origin: a floor inside the first chunk is one tile.
  storage::MemoryChunkStore store(test_metadata(kTileSceneVoxel, kTileSceneTau));
  write_field(store, Eigen::Vector3i(5, 5, 0), Eigen::Vector3i(50, 50, 40),
              [](const Eigen::Vector3d& p) { return p.z() - 1.0; });
  const fs::path dir = scratch_dir("tile_set_one");
  viewer_export::TileSetSettings settings;
  settings.tile_size_m = 100.0;
  settings.write_ply = false;
  const viewer_export::TileSetReport report =
      viewer_export::write_tile_set(store, dir.string(), settings);
  EXPECT_EQ(report.tiles, 1u);
  ASSERT_EQ(report.levels.size(), 1u);
  EXPECT_EQ(report.root.geometric_error_m, 0.0);
  EXPECT_FALSE(fs::exists(dir / "tiles/0/0_0.ply"));

  settings.level_ratio = 1.0;
  EXPECT_THROW(viewer_export::write_tile_set(store, dir.string(), settings), std::invalid_argument);
  settings.level_ratio = 0.25;
  settings.tiles_in_work = 0;
  EXPECT_THROW(viewer_export::write_tile_set(store, dir.string(), settings), std::invalid_argument);
  settings.tiles_in_work = 2;
  settings.tile_size_m = -1.0;
  EXPECT_THROW(viewer_export::write_tile_set(store, dir.string(), settings), std::invalid_argument);
  storage::MemoryChunkStore empty(test_metadata(kTileSceneVoxel, kTileSceneTau));
  settings.tile_size_m = 50.0;
  EXPECT_THROW(viewer_export::write_tile_set(empty, dir.string(), settings), std::runtime_error);
}

}  // namespace
}  // namespace featsense::test
