// The tiles' parts kept on disk between the two passes of the tiled navigation layers: what a
// tile takes is exactly what was put for it, in the order of the tiles it came from, whatever
// the order (and threads) of the puts, and nothing is left behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <thread>
#include <vector>

#include "tile_margins.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

mesh::TriangleMesh part_from(std::size_t from, bool with_normals) {
  mesh::TriangleMesh m;
  const auto f = static_cast<float>(from);
  m.vertices = {{f, 0.f, 0.f}, {f, 1.f, 0.f}, {f, 0.f, 1.f}, {f, 1.f, 1.f}};
  m.triangles = {{0, 1, 2}, {2, 1, 3}};
  if (with_normals) m.normals.assign(4, Eigen::Vector3f::UnitX());
  return m;
}

TEST(TileMargins, ATileTakesItsPartsInTheOrderOfTheirTilesAndNothingIsLeft) {
  const fs::path dir = fs::temp_directory_path() / "featsense_tile_margins" / ".margins";
  {
    TileMargins margins(dir);
    ASSERT_TRUE(fs::is_directory(dir));
    // Tile 1's neighbours put their parts from four threads, in no order.
    const std::vector<std::size_t> sources{7, 0, 5, 2};
    std::vector<std::thread> threads;
    for (std::size_t from : sources)
      threads.emplace_back([&margins, from] { margins.put(1, from, part_from(from, from % 2)); });
    for (std::thread& t : threads) t.join();
    margins.put(3, 1, part_from(1, true));

    const std::vector<mesh::TriangleMesh> parts = margins.take(1);
    ASSERT_EQ(parts.size(), 4u);
    const std::vector<std::size_t> ascending{0, 2, 5, 7};
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const mesh::TriangleMesh expected = part_from(ascending[k], ascending[k] % 2);
      EXPECT_EQ(parts[k].vertices, expected.vertices) << "part " << k;
      EXPECT_EQ(parts[k].triangles, expected.triangles) << "part " << k;
      EXPECT_EQ(parts[k].normals, expected.normals) << "part " << k;
    }
    EXPECT_TRUE(margins.take(1).empty()) << "a part is taken once";
    EXPECT_TRUE(margins.take(2).empty()) << "a tile nothing was put for";
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++files;
    EXPECT_EQ(files, 1u) << "the taken parts' files are removed, tile 3's stays";
  }
  EXPECT_FALSE(fs::exists(dir)) << "the folder goes with the margins";
  fs::remove_all(dir.parent_path());
}

TEST(TileMargins, APartThatCannotBeWrittenIsAnErrorNamingItsFile) {
  const fs::path dir = fs::temp_directory_path() / "featsense_tile_margins_gone";
  TileMargins margins(dir);
  fs::remove_all(dir);  // as if the disk or the folder went away under the run
  try {
    margins.put(0, 1, part_from(1, false));
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("0_from_1.part"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace featsense::app
