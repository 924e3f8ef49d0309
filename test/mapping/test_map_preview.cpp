// The live preview of a map pass: the chunks' meshes handed over while the map is made add up,
// after the last refresh, to the mesh of the map written (triangle for triangle), with every
// pose on the way; a small per-refresh budget only spreads the chunks over more refreshes.

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <vector>

#include "common/test_data.hpp"
#include "common/triangle_corners.hpp"
#include "featsense/mapping/mapper.hpp"
#include "featsense/mesh/marching_cubes.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"
#include "mapping/mapping_test_scenes.hpp"

namespace featsense::mapping {
namespace {

/// What a viewer keeps: the latest mesh of each chunk, and the refreshes as they came.
struct Watcher {
  std::mutex mutex;
  std::map<storage::ChunkKey, mesh::TriangleMesh> chunks;
  std::vector<MapPreview> refreshes;  ///< without their chunks

  void take(MapPreview preview) {
    std::lock_guard<std::mutex> lock(mutex);
    for (ChunkMesh& chunk : preview.chunks) chunks[chunk.key] = std::move(chunk.mesh);
    preview.chunks.clear();
    refreshes.push_back(std::move(preview));
  }
  mesh::TriangleMesh united() {
    mesh::TriangleMesh all;
    for (const auto& [key, part] : chunks) all = test::append_mesh(std::move(all), part);
    return all;
  }
};

void expect_preview_is_the_map(size_t max_chunks, const char* name) {
  const std::filesystem::path dir = test::scratch_dir(name);
  const slam::BoxRoomSettings room = test::small_room();
  MapperSettings settings = test::room_mapper_settings(room, dir / "map.h5");
  Watcher watcher;
  MapPreviewSettings preview;
  preview.interval_s = 0.0;  // a refresh after every scan whose previous one is meshed
  preview.max_chunks = max_chunks;
  preview.deliver = [&watcher](MapPreview update) { watcher.take(std::move(update)); };
  settings.preview = preview;
  Mapper mapper(settings);
  const std::unique_ptr<slam::ScanSource> source = slam::make_box_room_source(room);
  const MapResult result = map_source(*source, mapper);
  ASSERT_EQ(result.mapped().frames_mapped, 12u);

  ASSERT_GE(watcher.refreshes.size(), 2u);
  size_t poses = 0;
  for (size_t i = 0; i < watcher.refreshes.size(); ++i) {
    const MapPreview& refresh = watcher.refreshes[i];
    EXPECT_EQ(refresh.refresh, i + 1);
    EXPECT_EQ(refresh.last, i + 1 == watcher.refreshes.size());
    EXPECT_TRUE(refresh.has_latest_pose);
    poses += refresh.new_poses.size();
  }
  EXPECT_EQ(poses, 12u) << "every pose once";
  EXPECT_EQ(watcher.refreshes.back().chunks_waiting, 0u);
  EXPECT_EQ(watcher.refreshes.back().frames_mapped, 12u);
  // Timed on the integrating thread once per refresh it started (the last one's batches once).
  EXPECT_FALSE(result.mapped().timings.preview_ms.empty());
  EXPECT_LE(result.mapped().timings.preview_ms.size(), watcher.refreshes.size());
  size_t most_waiting = 0;
  for (const MapPreview& refresh : watcher.refreshes)
    most_waiting = std::max(most_waiting, refresh.chunks_waiting);
  if (max_chunks < 10) {
    EXPECT_GT(most_waiting, 0u) << "a backlog is reported";
  }

  storage::Hdf5ChunkStore store(dir / "map.h5");
  const mesh::TriangleMesh map_mesh = mesh::extract_mesh(store, {});
  ASSERT_GT(map_mesh.triangles.size(), 10000u);
  EXPECT_EQ(test::triangle_corners(watcher.united()), test::triangle_corners(map_mesh));
}

TEST(MapPreview, TheChunksHandedOverAddUpToTheMapsMesh) {
  expect_preview_is_the_map(128, "preview_whole");
}

TEST(MapPreview, ASmallBudgetSpreadsTheChunksOverMoreRefreshes) {
  expect_preview_is_the_map(3, "preview_small_budget");
}

}  // namespace
}  // namespace featsense::mapping
