#pragma once
// `featsense view`'s HTTP server: the page (built into the program), three.js (from Debian's
// libjs-three) and one output folder's content, at fixed routes only, so that no request can
// name a file of its own choosing.
//
//   /, /index.html, /viewer.js, /viewer.css   the page
//   /three/three.min.js, /three/OrbitControls.js, /three/FlyControls.js
//   /scene.json   counts, bounds, layers, paths (view_content.hpp)
//   /mesh.bin     the mesh (viewer_export/viewer_mesh_binary.hpp)
//   /plan.png     topdown.png, 404 where there is none
// or, serving a live run (live_view.hpp), the live page at / and
//   /live/status.json?path_from=N   the run's figures, the latest pose, the path from N on
//   /live/mesh.bin?since=V          the chunks changed after version V
// or, serving a tile set (view_tile_set.hpp), the tile-set page at / and
//   /tileset/tileset.json, /tileset/tiles/L/X_Y.glb   the files listed at start
//   /modules/...                    three.js and 3d-tiles-renderer, the files listed at start

#include <atomic>
#include <filesystem>
#include <memory>
#include <string>

#include "live_view.hpp"
#include "view_content.hpp"
#include "view_tile_set.hpp"

namespace featsense::app {

/// Where Debian's libjs-three puts three.js.
inline constexpr const char* kThreeJsFolder = "/usr/share/javascript/three";

class ViewServer {
 public:
  /// Reads three.js and its controls from `three_folder`; throws ViewError naming the file
  /// that is missing (and the package that brings it).
  ViewServer(ViewContent content, const std::filesystem::path& three_folder);
  /// Serves a live run's map as it grows (`featsense live --view`).
  ViewServer(std::shared_ptr<const LiveView> live, const std::filesystem::path& three_folder);
  /// Serves a tile set to the tile-set page (no Debian three.js needed).
  explicit ViewServer(TileSetSite tiles);
  ~ViewServer();
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  /// Binds to `host`:`port` (0: any free port) and returns the port; throws ViewError when
  /// the port is in use or the address cannot be bound.
  int bind(const std::string& host, int port);
  /// Serves until stop(); returns false when the server could not run.
  bool run();
  /// Ends run() from any thread (also before run() has started listening).
  void stop();

 private:
  struct Impl;
  /// The page and three.js; `home` is the page served at /.
  void serve_page(const std::filesystem::path& three_folder, const std::string& home);
  /// The page's files; `home` is served at / too.
  void serve_page_files(const std::string& home);
  std::unique_ptr<Impl> impl_;
};

}  // namespace featsense::app
