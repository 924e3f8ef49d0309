// Navigation layers to files: one mesh, or a tile set's tiles each with its neighbours.

#include "navigation_files.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "featsense/viewer_export/mesh_nav_h5_io.hpp"
#include "featsense/viewer_export/mesh_writer.hpp"
#include "featsense/viewer_export/surface_file_regions.hpp"
#include "json_output.hpp"
#include "progress.hpp"
#include "tile_margins.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

/// Tile sets whose full-resolution files take at most this much stay in memory whole.
constexpr std::uintmax_t kKeptWholeBytes = std::uintmax_t{256} << 20;

/// The bytes of the files a TileSetReader reads: the tiles of tiles.json.
std::uintmax_t full_resolution_bytes(const fs::path& dir) {
  std::uintmax_t bytes = 0;
  for (const viewer_export::TileSetEntry& entry : viewer_export::read_tile_set_index(dir)) {
    std::error_code error;
    const std::uintmax_t size = fs::file_size(dir / entry.file, error);
    if (error) return std::numeric_limits<std::uintmax_t>::max();  // the reader says why
    bytes += size;
  }
  return bytes;
}

/// Green (free) through yellow to red (cost just below 1); lethal vertices dark red.
Eigen::Matrix<uint8_t, 3, 1> cost_colour(float cost) {
  if (cost >= 1.0f) return {128, 0, 0};
  const float c = std::clamp(cost, 0.0f, 1.0f);
  const auto byte = [](float v) { return static_cast<uint8_t>(std::lround(v * 255.0f)); };
  return c < 0.5f ? Eigen::Matrix<uint8_t, 3, 1>(byte(2.0f * c), 255, 0)
                  : Eigen::Matrix<uint8_t, 3, 1>(255, byte(2.0f - 2.0f * c), 0);
}

/// The first `triangles` triangles of `whole` and the vertices they use, with their layers.
void keep_first_triangles(const mesh::TriangleMesh& whole, const mesh::NavigationLayers& layers,
                          std::size_t triangles, mesh::TriangleMesh* mesh,
                          mesh::NavigationLayers* kept) {
  std::vector<uint32_t> first(triangles);
  std::iota(first.begin(), first.end(), 0u);
  std::vector<uint64_t> source;
  *mesh = mesh::triangle_subset(whole, first, &source);
  for (uint64_t v : source) {
    kept->inclination_deg.push_back(layers.inclination_deg[v]);
    kept->roughness_deg.push_back(layers.roughness_deg[v]);
    kept->height_diff_m.push_back(layers.height_diff_m[v]);
    kept->cost.push_back(layers.cost[v]);
  }
  kept->lethal_faces.assign(layers.lethal_faces.begin(),
                            layers.lethal_faces.begin() + static_cast<std::ptrdiff_t>(triangles));
}

}  // namespace

std::size_t write_navigation_mesh(const std::string& path, mesh::TriangleMesh& mesh,
                                  const mesh::NavigationLayers& layers) {
  if (!mesh.has_normals()) mesh.normals = mesh::vertex_normals(mesh);
  viewer_export::MeshAttributes attributes;
  attributes.scalars = {{"inclination_deg", layers.inclination_deg},
                        {"roughness_deg", layers.roughness_deg},
                        {"height_diff_m", layers.height_diff_m},
                        {"cost", layers.cost}};
  // Lethal per vertex too: the formats without face layers (PLY, glTF) carry it this way.
  std::vector<float> lethal_vertices(mesh.vertices.size(), 0.0f);
  std::vector<float> lethal_faces(layers.lethal_faces.size(), 0.0f);
  std::size_t lethal_count = 0;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (layers.lethal_faces[f] == 0) continue;
    lethal_faces[f] = 1.0f;
    ++lethal_count;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(mesh.triangles[f][k]);
      if (layers.cost[v] >= 1.0f) lethal_vertices[v] = 1.0f;
    }
  }
  attributes.scalars.push_back({"lethal", lethal_vertices});
  for (const float cost : layers.cost) attributes.colors.push_back(cost_colour(cost));
  if (viewer_export::mesh_extension(path) == ".h5") {
    viewer_export::write_mesh_nav_h5(path, mesh, attributes, {{"lethal", lethal_faces}});
  } else {
    viewer_export::write_mesh(path, mesh, attributes);
  }
  return lethal_count;
}

nlohmann::json write_navigation_tiles(const fs::path& tile_set_dir, const fs::path& out_dir,
                                      const std::string& extension,
                                      const mesh::NavigationSettings& settings, bool quiet) {
  // Two passes over the tiles, a few tiles at once (at most 4 threads: a tile's work takes
  // about 0.2 GB): the first cuts from each tile the triangles its neighbours need and keeps
  // them on disk (TileMargins); the second computes each tile's layers with those parts of its
  // neighbours. Every tile is read twice, and memory is that of the tiles in work; except in a
  // tile set whose files take at most kKeptWholeBytes, which stays in memory from the first pass
  // to the second (its tiles take about what their files do) and is read once.
  const std::size_t workers =
      std::clamp<std::size_t>(static_cast<std::size_t>(tbb::info::default_concurrency()), 1, 4);
  const viewer_export::TileSetReader reader(tile_set_dir,
                                            full_resolution_bytes(tile_set_dir) <= kKeptWholeBytes
                                                ? std::numeric_limits<std::size_t>::max()
                                                : workers);
  const std::vector<viewer_export::TileSetEntry>& tiles = reader.tiles();
  fs::create_directories(out_dir);
  // A tile's vertex looks at the vertices within the radius and at their normals, made from
  // their faces. Every such vertex lies in the tile's box grown by the radius, and a face of
  // a vertex in that box meets the box: the triangles meeting it are all the layers need.
  // (The centimetre covers the float rounding of the radius test.)
  const double reach = settings.radius_m + 0.01;
  const auto around = [&](std::size_t i) {
    return Eigen::AlignedBox3d(tiles[i].bounds.min().array() - reach,
                               tiles[i].bounds.max().array() + reach);
  };
  TileMargins margins(out_dir / ".margins");
  const auto cut_margins = [&](std::size_t j) {
    const std::shared_ptr<const mesh::TriangleMesh> tile = reader.tile(j);
    for (std::size_t i = 0; i < tiles.size(); ++i) {
      if (i == j) continue;
      const Eigen::AlignedBox3d reach_of_i = around(i);
      if (!tiles[j].bounds.intersects(reach_of_i)) continue;
      const mesh::TriangleMesh part = mesh::triangles_meeting(*tile, reach_of_i);
      if (!part.triangles.empty()) margins.put(i, j, part);
    }
  };
  const auto navigate_tile = [&](std::size_t i) -> nlohmann::json {
    // The tile first, then its neighbours' parts: welded, the tile's triangles stay the first.
    const std::shared_ptr<const mesh::TriangleMesh> own_tile = reader.tile(i);
    std::vector<mesh::TriangleMesh> near = margins.take(i);
    std::vector<const mesh::TriangleMesh*> parts{own_tile.get()};
    for (const mesh::TriangleMesh& part : near) parts.push_back(&part);
    // A vertex on a cut has its faces on both sides (for normals computed from faces) and its
    // neighbours across it (roughness, height difference).
    const mesh::TriangleMesh welded = reader.weld(parts);
    const std::size_t own = own_tile->triangles.size();
    near.clear();
    const mesh::NavigationLayers layers = mesh::compute_navigation_layers(welded, settings);
    mesh::TriangleMesh tile;
    mesh::NavigationLayers tile_layers;
    keep_first_triangles(welded, layers, own, &tile, &tile_layers);
    const std::string name =
        std::to_string(tiles[i].x) + "_" + std::to_string(tiles[i].y) + extension;
    const std::size_t tile_lethal =
        write_navigation_mesh((out_dir / name).string(), tile, tile_layers);
    return {{"x", tiles[i].x},
            {"y", tiles[i].y},
            {"file", name},
            {"triangles", own},
            {"lethal_triangles", tile_lethal}};
  };
  // Each tile's file depends on the tile set alone, so the order of the work does not matter;
  // the index lists the tiles in the tile set's order.
  std::vector<nlohmann::json> entries(tiles.size());
  Progress progress("navmesh", 2 * tiles.size(), quiet);
  std::mutex progress_mutex;
  std::size_t done = 0;
  const auto for_each_tile = [&](const std::function<void(std::size_t)>& work) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tiles.size(), 1),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i != range.end(); ++i) {
                          work(i);
                          const std::lock_guard<std::mutex> lock(progress_mutex);
                          progress.update(++done);
                        }
                      });
  };
  tbb::task_arena arena(static_cast<int>(workers));
  arena.execute([&] {
    for_each_tile(cut_margins);
    for_each_tile([&](std::size_t i) { entries[i] = navigate_tile(i); });
  });
  progress.finish();
  nlohmann::json listed = nlohmann::json::array();
  std::size_t triangles = 0;
  std::size_t lethal = 0;
  for (nlohmann::json& entry : entries) {
    triangles += entry["triangles"].get<std::size_t>();
    lethal += entry["lethal_triangles"].get<std::size_t>();
    listed.push_back(std::move(entry));
  }
  const nlohmann::json index = {{"tile_set", tile_set_dir.string()},
                                {"tiles", listed},
                                {"triangles", triangles},
                                {"lethal_triangles", lethal},
                                {"max_slope_deg", settings.max_slope_deg},
                                {"max_step_m", settings.max_step_m},
                                {"radius_m", settings.radius_m}};
  write_json(index, (out_dir / "navmesh.json").string());
  return index;
}

}  // namespace featsense::app
