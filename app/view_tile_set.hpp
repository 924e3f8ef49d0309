#pragma once
// What `featsense view` serves for a tile set (`featsense mesh --tiles DIR`): the tileset's
// files and the npm modules of its page (three.js, 3d-tiles-renderer), each listed once when
// the server starts. A request names a file only as a key into these lists, never as a path.

#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>

namespace featsense::app {

/// Where scripts/install-web.sh installs the page's modules (the source tree's
/// viewer_export/web/npm/node_modules).
std::filesystem::path default_web_modules_folder();

struct TileSetSite {
  std::filesystem::path folder;  ///< holds tileset.json
  /// Route under /tileset/ ("tileset.json", "tiles/0/3_4.glb") -> file.
  std::map<std::string, std::filesystem::path> tileset_files;
  /// Route under /modules/ ("three/build/three.module.js") -> file.
  std::map<std::string, std::filesystem::path> module_files;
  std::size_t tiles = 0;  ///< GLB files: the tiles of every level
};

/// True where `folder` holds a tileset.json.
bool is_tile_set_folder(const std::filesystem::path& folder);

/// The tile set `featsense view FOLDER` shows, if any: FOLDER itself where it holds a
/// tileset.json, or FOLDER/tiles where FOLDER is the output of `featsense map --tiles` (a
/// tiles/tileset.json and no mesh.ply or mesh.glb of its own).
std::optional<std::filesystem::path> tile_set_to_view(const std::filesystem::path& folder);

/// Lists the tile set's files and the modules; throws ViewError when the tileset or a module
/// is missing (saying how to install the modules).
TileSetSite load_tile_set_site(const std::filesystem::path& folder,
                               const std::filesystem::path& modules_folder);

}  // namespace featsense::app
