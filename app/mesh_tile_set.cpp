#include "mesh_tile_set.hpp"

#include <cstdio>

#include "featsense/bench/measurements.hpp"
#include "progress.hpp"

namespace featsense::app {

nlohmann::json write_tile_set_with_progress(storage::ChunkStore& store, const std::string& dir,
                                            const viewer_export::TileSetSettings& settings,
                                            bool quiet, viewer_export::TileSetReport* whole) {
  viewer_export::TileSetSettings with_progress = settings;
  Progress progress("tiles", std::nullopt, quiet);
  with_progress.progress = [&](std::size_t done, std::size_t total) {
    progress.update(done, "of " + std::to_string(total));
  };
  viewer_export::TileSetReport report = viewer_export::write_tile_set(store, dir, with_progress);
  progress.finish();

  nlohmann::json levels = nlohmann::json::array();
  for (const viewer_export::TileSetLevel& level : report.levels) {
    levels.push_back({{"level", level.level},
                      {"tiles", level.tiles},
                      {"triangles", level.triangles},
                      {"max_geometric_error_m", level.max_geometric_error_m}});
  }
  nlohmann::json figures = {{"dir", dir},
                            {"tileset", dir + "/tileset.json"},
                            {"index", dir + "/tiles.json"},
                            {"tile_size_m", report.tile_size_m},
                            {"tiles", report.tiles},
                            {"triangles", report.triangles},
                            {"vertices", report.vertices},
                            {"chunks", report.chunks},
                            {"levels", levels},
                            {"meshing_s", report.meshing_seconds},
                            {"simplifying_s", report.simplifying_seconds},
                            {"writing_s", report.writing_seconds},
                            {"seconds", report.seconds},
                            {"peak_rss_mb", bench::peak_rss_mb()}};
  if (report.cleanup) {
    const mesh::CleanupReport& c = *report.cleanup;
    figures["cleanup"] = {{"input_triangles", c.input_triangles},
                          {"output_triangles", c.output_triangles},
                          {"removed_components", c.removed_components},
                          {"removed_component_triangles", c.removed_component_triangles},
                          {"components_kept_on_cuts", c.components_kept_on_cuts},
                          {"non_manifold_vertices_fixed", c.non_manifold_vertices_fixed},
                          {"holes_filled", c.holes_filled},
                          {"holes_left", c.holes_left},
                          {"borders_on_cuts", c.borders_on_cuts},
                          {"seconds", c.seconds}};
  }
  if (!quiet) {
    std::printf(
        "%s: %zu tiles of %.1f m, %zu triangles from %zu chunks, %zu levels, in %.1f s "
        "(meshing %.1f s, levels %.1f s, files %.1f s); tileset.json, tiles.json\n",
        dir.c_str(), report.tiles, report.tile_size_m, report.triangles, report.chunks,
        report.levels.size(), report.seconds, report.meshing_seconds, report.simplifying_seconds,
        report.writing_seconds);
  }
  if (whole != nullptr) *whole = std::move(report);
  return figures;
}

}  // namespace featsense::app
