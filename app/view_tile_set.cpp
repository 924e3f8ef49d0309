#include "view_tile_set.hpp"

#include <system_error>

#include "view_content.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

/// Every file with `extension` under `root`/`sub`, by its path relative to `root` (forward
/// slashes), into `files`; false when `root`/`sub` is not a folder.
bool list_files(const fs::path& root, const std::string& sub, const std::string& extension,
                std::map<std::string, fs::path>& files) {
  const fs::path start = root / sub;
  std::error_code error;
  if (!fs::is_directory(start, error)) return false;
  for (fs::recursive_directory_iterator it(start, error), end; !error && it != end;
       it.increment(error)) {
    if (!it->is_regular_file(error) || it->path().extension() != extension) continue;
    files[it->path().lexically_relative(root).generic_string()] = it->path();
  }
  return true;
}

}  // namespace

fs::path default_web_modules_folder() {
  return fs::path(FEATSENSE_SOURCE_DIR) / "viewer_export" / "web" / "npm" / "node_modules";
}

bool is_tile_set_folder(const fs::path& folder) {
  std::error_code error;
  return fs::is_regular_file(folder / "tileset.json", error);
}

std::optional<fs::path> tile_set_to_view(const fs::path& folder) {
  if (is_tile_set_folder(folder)) return folder;
  std::error_code error;
  const bool has_mesh =
      fs::exists(folder / "mesh.ply", error) || fs::exists(folder / "mesh.glb", error);
  if (!has_mesh && is_tile_set_folder(folder / "tiles")) return folder / "tiles";
  return std::nullopt;
}

TileSetSite load_tile_set_site(const fs::path& folder, const fs::path& modules_folder) {
  TileSetSite site;
  site.folder = folder;
  if (!is_tile_set_folder(folder))
    throw ViewError(folder.string() +
                    ": no tileset.json (make one with featsense mesh MAP "
                    "--tiles DIR)");
  site.tileset_files["tileset.json"] = folder / "tileset.json";
  list_files(folder, "tiles", ".glb", site.tileset_files);
  site.tiles = site.tileset_files.size() - 1;

  const std::string install =
      " (the tile set's page needs three.js and 3d-tiles-renderer from "
      "npm: run scripts/install-web.sh, or give --web-modules DIR)";
  const bool found =
      list_files(modules_folder, "three/build", ".js", site.module_files) &&
      list_files(modules_folder, "three/examples/jsm", ".js", site.module_files) &&
      list_files(modules_folder, "3d-tiles-renderer/build", ".js", site.module_files);
  for (const char* needed : {"three/build/three.module.js", "3d-tiles-renderer/build/index.js",
                             "three/examples/jsm/controls/OrbitControls.js"}) {
    if (!found || site.module_files.count(needed) == 0)
      throw ViewError((modules_folder / needed).string() + " is missing" + install);
  }
  return site;
}

}  // namespace featsense::app
