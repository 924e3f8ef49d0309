#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <tuple>

#include "featsense/mesh/tiled_point_file.hpp"
#include "featsense/mesh/triangle_mesh.hpp"

namespace featsense::test {
namespace {

namespace fs = std::filesystem;
using Voxel = std::tuple<int64_t, int64_t, int64_t>;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(::testing::TempDir()) / ("tiled_points_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

Voxel voxel_of(const Eigen::Vector3f& p, double v) {
  return {static_cast<int64_t>(std::floor(p.x() / v)), static_cast<int64_t>(std::floor(p.y() / v)),
          static_cast<int64_t>(std::floor(p.z() / v))};
}

/// Points of a walk through a street: many land on voxels seen before, some tiles are left
/// and come back (a loop), coordinates on both sides of zero.
std::vector<Eigen::Vector3f> street_points(size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> along(-9.0f, 9.0f);
  std::uniform_real_distribution<float> across(-1.5f, 1.5f);
  std::uniform_real_distribution<float> height(-0.3f, 0.3f);
  std::vector<Eigen::Vector3f> points;
  for (size_t i = 0; i < count; ++i) {
    // There and back twice along x, then along y.
    const float leg = static_cast<float>(i % (count / 4)) / static_cast<float>(count / 4);
    const float s = (i / (count / 4)) % 2 == 0 ? leg : 1.0f - leg;
    const float x = -9.0f + 18.0f * s + 0.3f * along(rng) / 9.0f;
    if (i < count / 2) {
      points.emplace_back(x, across(rng), height(rng));
    } else {
      points.emplace_back(across(rng), x, height(rng));
    }
  }
  return points;
}

TEST(TiledPointFile, HoldsTheFirstPointOfEachVoxelWhateverIsForgotten) {
  const fs::path dir = scratch("thinning");
  const std::vector<Eigen::Vector3f> points = street_points(200000, 3);
  mesh::TiledPointSettings settings;
  settings.voxel_size_m = 0.05;
  settings.tile_size_m = 2.0;
  // A budget of a few tiles' voxels: tiles are forgotten and come back.
  settings.remembered_voxels = 3000;
  mesh::TiledPointWriter writer(dir / "points.ply", settings);
  for (const Eigen::Vector3f& p : points) writer.add(p);
  writer.add(Eigen::Vector3f(std::nanf(""), 0, 0));  // dropped
  const size_t written = writer.finish();

  // The brute-force reference: the first point of each voxel in the order given.
  std::set<Voxel> seen;
  std::vector<Eigen::Vector3f> expected;
  for (const Eigen::Vector3f& p : points) {
    if (seen.insert(voxel_of(p, settings.voxel_size_m)).second) expected.push_back(p);
  }
  ASSERT_EQ(written, expected.size());
  EXPECT_FALSE(fs::exists(dir / "points.ply.parts"));

  const mesh::TiledPointFile file(dir / "points.ply");
  ASSERT_TRUE(file.tiled());
  EXPECT_TRUE(mesh::is_tiled_point_file(dir / "points.ply"));
  EXPECT_EQ(file.points(), expected.size());
  EXPECT_GT(file.tiles().size(), 20u);
  auto key = [](const Eigen::Vector3f& p) { return std::make_tuple(p.x(), p.y(), p.z()); };
  std::vector<std::tuple<float, float, float>> got;
  for (const mesh::TiledPointFile::Tile& tile : file.tiles()) {
    for (const Eigen::Vector3f& p : file.read_tile(tile)) {
      // Each point in its tile's square (and the millimetre of slack).
      EXPECT_TRUE(tile.bounds.contains(p.cast<double>()));
      got.push_back(key(p));
    }
  }
  std::vector<std::tuple<float, float, float>> want;
  for (const Eigen::Vector3f& p : expected) want.push_back(key(p));
  std::sort(got.begin(), got.end());
  std::sort(want.begin(), want.end());
  EXPECT_EQ(got, want);
}

TEST(TiledPointFile, ReadsARegionAsTheBruteForceFilterDoes) {
  const fs::path dir = scratch("region");
  const std::vector<Eigen::Vector3f> points = street_points(40000, 5);
  mesh::TiledPointSettings settings;
  settings.voxel_size_m = 0.05;
  settings.tile_size_m = 3.0;
  mesh::TiledPointWriter writer(dir / "points.ply", settings);
  for (const Eigen::Vector3f& p : points) writer.add(p);
  writer.finish();
  const mesh::TiledPointFile file(dir / "points.ply");
  const std::vector<Eigen::Vector3f> all = file.read(Eigen::AlignedBox3d());
  ASSERT_EQ(all.size(), file.points());
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-4.1, -1.0, -0.1), Eigen::Vector3d(2.7, 5.3, 1.0));
  const size_t inside =
      static_cast<size_t>(std::count_if(all.begin(), all.end(), [&](const Eigen::Vector3f& p) {
        return box.contains(p.cast<double>());
      }));
  EXPECT_GT(inside, 100u);
  EXPECT_EQ(file.read(box).size(), inside);
  EXPECT_TRUE(file.bounds().contains(box.min().cwiseMax(file.bounds().min())));
}

TEST(TiledPointFile, APlainPointPlyIsOneTileAndABrokenOneAnError) {
  const fs::path dir = scratch("plain");
  {
    std::ofstream out(dir / "plain.ply", std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
           "property float y\nproperty float z\nend_header\n";
    const float values[6] = {1, 2, 3, -4, 5, 6};
    out.write(reinterpret_cast<const char*>(values), sizeof(values));
  }
  const mesh::TiledPointFile plain(dir / "plain.ply");
  EXPECT_FALSE(plain.tiled());
  EXPECT_FALSE(mesh::is_tiled_point_file(dir / "plain.ply"));
  ASSERT_EQ(plain.tiles().size(), 1u);
  EXPECT_EQ(plain.bounds().min().x(), -4.0);
  EXPECT_EQ(
      plain.read(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(9, 9, 9))).size(),
      1u);

  // Cut short: the error names the file and says so.
  const fs::path cut = dir / "cut.ply";
  {
    mesh::TiledPointWriter writer(dir / "whole.ply", {0.05, 1.0, 1000});
    for (const Eigen::Vector3f& p : street_points(2000, 9)) writer.add(p);
    writer.finish();
    fs::copy_file(dir / "whole.ply", cut);
    fs::resize_file(cut, fs::file_size(cut) - 7);
  }
  try {
    mesh::TiledPointFile broken(cut);
    FAIL() << "a truncated file was read";
  } catch (const mesh::MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.ply: truncated"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "text.ply") << "not a ply\n";
  EXPECT_THROW(mesh::TiledPointFile(dir / "text.ply"), mesh::MeshError);
  EXPECT_THROW(mesh::TiledPointWriter(dir / "bad.ply", {0.0, 1.0, 10}), mesh::MeshError);
}

}  // namespace
}  // namespace featsense::test
