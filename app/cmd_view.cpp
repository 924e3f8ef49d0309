// featsense view OUT/: the map in the browser. A small HTTP server on this machine serves the
// page, the mesh, the paths and the plan view of one output folder, or a tile set streamed by
// level of detail, until Ctrl+C.

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "commands.hpp"
#include "stop_signal.hpp"
#include "view_content.hpp"
#include "view_server.hpp"

namespace featsense::app {
namespace {

using Clock = std::chrono::steady_clock;

struct ViewOptions {
  std::string folder;
  std::string host = "127.0.0.1";
  int port = 8765;
  std::string three_folder = kThreeJsFolder;
  std::string web_modules = default_web_modules_folder().string();
  ViewSettings settings;
};

void run_view(const ViewOptions& options, const CliContext& context) {
  const Clock::time_point start = Clock::now();
  std::unique_ptr<ViewServer> server_owner;
  std::string loaded;
  if (const std::optional<std::filesystem::path> tiles = tile_set_to_view(options.folder)) {
    TileSetSite site = load_tile_set_site(*tiles, options.web_modules);
    loaded = "tile set " + tiles->string() + " (" + std::to_string(site.tiles) +
             " tiles of every level)";
    server_owner = std::make_unique<ViewServer>(std::move(site));
  } else {
    loaded = options.folder;
    server_owner = std::make_unique<ViewServer>(load_view_content(options.folder, options.settings),
                                                options.three_folder);
  }
  ViewServer& server = *server_owner;
  const int port = server.bind(options.host, options.port);
  // Before the URL is printed: a Ctrl+C the moment it appears (a script that reads the URL
  // and stops the server) closes the server cleanly instead of killing the process.
  const StopSignal stop_signal("closing the viewer's server");
  if (!context.quiet) {
    std::printf("featsense view: %s loaded in %.1f s\n", loaded.c_str(),
                std::chrono::duration<double>(Clock::now() - start).count());
  }
  // The URL always: it is what the command is for (also with --quiet).
  std::printf("http://%s:%d/\n", options.host.c_str(), port);
  if (!context.quiet) std::printf("Ctrl+C stops the server\n");
  std::fflush(stdout);

  std::atomic<bool> served{true};
  std::thread listener([&] { served = server.run(); });
  while (!stop_signal.requested() && served)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  server.stop();
  listener.join();
  if (!served)
    throw ViewError("the server stopped: cannot accept connections on port " +
                    std::to_string(port));
}

}  // namespace

Command register_view(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<ViewOptions>();
  CLI::App* command = app.add_subcommand(
      "view",
      "Show an output folder (mesh, paths, plan view) in the browser: serves it on this machine "
      "and prints the URL; Ctrl+C stops");
  command
      ->add_option("FOLDER", options->folder,
                   "Output folder of featsense map, demo or mesh, or a tile set (mesh --tiles)")
      ->required();
  command->add_option("--port", options->port, "Port; 0 takes any free one")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  command
      ->add_option("--host", options->host,
                   "Address to listen on (another than 127.0.0.1 shows the map to the network)")
      ->capture_default_str();
  command
      ->add_option("--max-triangles", options->settings.max_triangles,
                   "Above this, the page gets a coarser mesh (vertices merged on a grid)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--three", options->three_folder, "Folder of three.js (Debian's libjs-three)")
      ->capture_default_str();
  command
      ->add_option("--web-modules", options->web_modules,
                   "For a tile set: the npm modules three and 3d-tiles-renderer "
                   "(scripts/install-web.sh)")
      ->capture_default_str();
  return {command, [options, &context] { run_view(*options, context); }};
}

}  // namespace featsense::app
