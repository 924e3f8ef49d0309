#include "view_server.hpp"

#include <httplib.h>
#include <sys/socket.h>

#include <chrono>
#include <cstdlib>
#include <map>
#include <thread>
#include <utility>

#include "featsense/viewer_export/viewer_page.hpp"

namespace featsense::app {
namespace {

namespace fs = std::filesystem;

// cpp-httplib compresses a response (brotli where the browser accepts it) when its type is
// text/*, or exactly application/javascript or application/json: seconds for three.js, for
// nothing on this machine's loopback. These spellings are what browsers accept and it leaves
// alone.
constexpr const char* kJavaScript = "application/javascript; charset=utf-8";
constexpr const char* kJson = "application/json; charset=utf-8";

struct StaticFile {
  std::string content_type;
  std::string body;
};

/// The files of three.js the page loads, by their route under /three/.
std::map<std::string, StaticFile> read_three_js(const fs::path& folder) {
  const std::pair<const char*, const char*> files[] = {
      {"three.min.js", "build/three.min.js"},
      {"OrbitControls.js", "examples/js/controls/OrbitControls.js"},
      {"FlyControls.js", "examples/js/controls/FlyControls.js"}};
  std::map<std::string, StaticFile> result;
  for (const auto& [route, relative] : files) {
    const fs::path file = folder / relative;
    std::optional<std::string> text = read_file_bytes(file);
    if (!text)
      throw ViewError("three.js is missing: " + file.string() +
                      " cannot be read (install Debian's libjs-three)");
    result[route] = {kJavaScript, std::move(*text)};
  }
  return result;
}

/// Only SO_REUSEADDR (a restart may reuse a port in TIME_WAIT): httplib's default adds
/// SO_REUSEPORT, which would let a second server share a port that is in use.
void reuse_address_only(socket_t sock) {
  int yes = 1;
  setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
}

}  // namespace

struct ViewServer::Impl {
  ViewContent content;
  TileSetSite tiles;
  std::shared_ptr<const LiveView> live;
  std::map<std::string, StaticFile> three;
  httplib::Server server;
  std::atomic<bool> started{false};
  std::atomic<bool> stop_requested{false};
  std::atomic<bool> finished{false};
};

void ViewServer::serve_page_files(const std::string& home) {
  httplib::Server& server = impl_->server;
  server.set_socket_options(reuse_address_only);
  for (const viewer_export::PageFile& file : viewer_export::viewer_page_files()) {
    const auto serve = [&file](const httplib::Request&, httplib::Response& response) {
      response.set_content(file.body, file.content_type.c_str());
    };
    server.Get(file.path, serve);
    if (file.path == home) server.Get("/", serve);
  }
}

void ViewServer::serve_page(const fs::path& three_folder, const std::string& home) {
  impl_->three = read_three_js(three_folder);
  serve_page_files(home);
  httplib::Server& server = impl_->server;
  for (const auto& [route, file] : impl_->three) {
    const StaticFile* served = &file;
    server.Get("/three/" + route, [served](const httplib::Request&, httplib::Response& response) {
      response.set_content(served->body, served->content_type.c_str());
    });
  }
}

ViewServer::ViewServer(ViewContent content, const fs::path& three_folder)
    : impl_(std::make_unique<Impl>()) {
  serve_page(three_folder, "/index.html");
  impl_->content = std::move(content);
  Impl& state = *impl_;
  httplib::Server& server = state.server;
  server.Get("/scene.json", [&state](const httplib::Request&, httplib::Response& response) {
    response.set_header("Cache-Control", "no-store");
    response.set_content(state.content.scene.dump(), kJson);
  });
  server.Get("/mesh.bin", [&state](const httplib::Request&, httplib::Response& response) {
    // Not kept in the browser's cache: writing megabytes there slows the page's load, and the
    // next start of the server may serve another mesh.
    response.set_header("Cache-Control", "no-store");
    response.set_content(state.content.mesh_binary, "application/octet-stream");
  });
  server.Get("/plan.png", [&state](const httplib::Request&, httplib::Response& response) {
    if (state.content.plan_png.empty()) {
      response.status = 404;
      response.set_content("this folder has no plan view (topdown.png)", "text/plain");
      return;
    }
    response.set_content(state.content.plan_png, "image/png");
  });
}

namespace {

/// A query parameter as a count; 0 where it is missing or not a number.
uint64_t count_parameter(const httplib::Request& request, const char* name) {
  if (!request.has_param(name)) return 0;
  const std::string text = request.get_param_value(name);
  char* end = nullptr;
  const unsigned long long value = std::strtoull(text.c_str(), &end, 10);
  return end != text.c_str() && *end == '\0' ? value : 0;
}

}  // namespace

ViewServer::ViewServer(std::shared_ptr<const LiveView> live, const fs::path& three_folder)
    : impl_(std::make_unique<Impl>()) {
  serve_page(three_folder, "/live.html");
  impl_->live = std::move(live);
  const LiveView* view = impl_->live.get();
  httplib::Server& server = impl_->server;
  server.Get(
      "/live/status.json", [view](const httplib::Request& request, httplib::Response& response) {
        response.set_header("Cache-Control", "no-store");
        response.set_content(view->status(count_parameter(request, "path_from")).dump(), kJson);
      });
  server.Get("/live/mesh.bin",
             [view](const httplib::Request& request, httplib::Response& response) {
               response.set_header("Cache-Control", "no-store");
               response.set_content(view->changes_since(count_parameter(request, "since")),
                                    "application/octet-stream");
             });
}

namespace {

const char* content_type_of(const fs::path& file) {
  const std::string extension = file.extension().string();
  if (extension == ".js") return kJavaScript;
  if (extension == ".json") return kJson;
  if (extension == ".glb") return "model/gltf-binary";
  return "application/octet-stream";
}

/// Serves `prefix`(.*) from `files`, the captured rest of the path only a key into it.
void serve_listed(httplib::Server& server, const std::string& prefix,
                  const std::map<std::string, fs::path>* files) {
  server.Get(prefix + "(.*)",
             [files](const httplib::Request& request, httplib::Response& response) {
               const auto found = files->find(request.matches[1].str());
               std::optional<std::string> bytes;
               if (found != files->end()) bytes = read_file_bytes(found->second);
               if (!bytes) {
                 response.status = 404;
                 response.set_content("no such file", "text/plain");
                 return;
               }
               response.set_content(std::move(*bytes), content_type_of(found->second));
             });
}

}  // namespace

ViewServer::ViewServer(TileSetSite tiles) : impl_(std::make_unique<Impl>()) {
  serve_page_files("/tiles.html");
  impl_->tiles = std::move(tiles);
  serve_listed(impl_->server, "/tileset/", &impl_->tiles.tileset_files);
  serve_listed(impl_->server, "/modules/", &impl_->tiles.module_files);
}

ViewServer::~ViewServer() = default;

int ViewServer::bind(const std::string& host, int port) {
  if (port == 0) {
    const int bound = impl_->server.bind_to_any_port(host);
    if (bound < 0)
      throw ViewError("cannot listen on " + host + ": no free port, or no such address");
    return bound;
  }
  if (!impl_->server.bind_to_port(host, port))
    throw ViewError("cannot listen on " + host + ":" + std::to_string(port) +
                    ": the port is in use (or the address is not this machine's); choose "
                    "another with --port N, or --port 0 for any free one");
  return port;
}

bool ViewServer::run() {
  impl_->started = true;
  if (impl_->stop_requested) return true;
  const bool ok = impl_->server.listen_after_bind();
  impl_->finished = true;
  return ok;
}

void ViewServer::stop() {
  // httplib's stop() does nothing before the server is listening: wait for that, or for run()
  // to have given up; where run() has not begun, it will not listen at all.
  impl_->stop_requested = true;
  while (impl_->started && !impl_->server.is_running() && !impl_->finished)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  impl_->server.stop();
}

}  // namespace featsense::app
