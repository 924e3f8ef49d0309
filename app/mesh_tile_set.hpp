#pragma once
// `featsense mesh --tiles DIR`: the map as a tile set (viewer_export/tile_set.hpp) with a
// progress line, a summary and its figures for --json.

#include <nlohmann/json.hpp>

#include <string>

#include "featsense/storage/chunk_store.hpp"
#include "featsense/viewer_export/tile_set.hpp"

namespace featsense::app {

/// Writes the tile set, prints its summary (unless quiet) and returns its figures; the whole
/// report goes to `report` where given.
nlohmann::json write_tile_set_with_progress(storage::ChunkStore& store, const std::string& dir,
                                            const viewer_export::TileSetSettings& settings,
                                            bool quiet,
                                            viewer_export::TileSetReport* report = nullptr);

}  // namespace featsense::app
