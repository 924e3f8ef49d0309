// featsense view's server: its routes against an output folder, over HTTP on a free port.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/view_test_folder.hpp"
#include "common/test_data.hpp"
#include "featsense/viewer_export/viewer_mesh_binary.hpp"
#include "live_view.hpp"
#include "view_content.hpp"
#include "view_server.hpp"

// Last: <resolv.h>, which httplib.h includes, defines a macro `_res` that Eigen's headers use
// as a parameter name.
#include <httplib.h>

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

uint32_t u32_at(const std::string& bytes, size_t offset) {
  uint32_t value = 0;
  std::memcpy(&value, bytes.data() + offset, sizeof(value));
  return value;
}

/// The server on a free port of 127.0.0.1, listening in a thread of its own until the end.
class RunningServer {
 public:
  explicit RunningServer(app::ViewContent content, const fs::path& three = app::kThreeJsFolder)
      : server_(std::move(content), three),
        port_(server_.bind("127.0.0.1", 0)),
        thread_([this] { server_.run(); }),
        client_("127.0.0.1", port_) {}
  /// Serving a live run's view.
  explicit RunningServer(std::shared_ptr<const app::LiveView> live)
      : server_(std::move(live), app::kThreeJsFolder),
        port_(server_.bind("127.0.0.1", 0)),
        thread_([this] { server_.run(); }),
        client_("127.0.0.1", port_) {}
  ~RunningServer() {
    server_.stop();
    thread_.join();
  }
  httplib::Client& client() { return client_; }

 private:
  app::ViewServer server_;
  int port_;
  std::thread thread_;
  httplib::Client client_;
};

TEST(ViewServer, ServesThePageThreeJsAndTheFolder) {
  if (!fs::is_directory(app::kThreeJsFolder)) GTEST_SKIP() << "libjs-three is not installed";
  const fs::path dir = scratch_dir("view_server");
  const mesh::TriangleMesh room = write_view_test_folder(dir);
  RunningServer server(app::load_view_content(dir));
  httplib::Client& client = server.client();

  for (const char* path : {"/", "/index.html"}) {
    const auto page = client.Get(path);
    ASSERT_TRUE(page) << path;
    EXPECT_EQ(page->status, 200);
    EXPECT_NE(page->body.find("viewer.js"), std::string::npos);
    EXPECT_NE(page->get_header_value("Content-Type").find("text/html"), std::string::npos);
  }
  for (const char* path : {"/viewer.js", "/viewer.css", "/three/three.min.js",
                           "/three/OrbitControls.js", "/three/FlyControls.js"}) {
    const auto file = client.Get(path);
    ASSERT_TRUE(file) << path;
    EXPECT_EQ(file->status, 200) << path;
    EXPECT_GT(file->body.size(), 1000u) << path;
  }
  EXPECT_NE(client.Get("/three/three.min.js")->body.find("REVISION"), std::string::npos);

  const auto scene_response = client.Get("/scene.json");
  ASSERT_TRUE(scene_response);
  const nlohmann::json scene = nlohmann::json::parse(scene_response->body);
  EXPECT_EQ(scene["mesh"]["triangles"], room.triangles.size());
  EXPECT_EQ(scene["mesh"]["simplified"], false);
  EXPECT_EQ(scene["mesh"]["layers"], nlohmann::json::array({"signed_distance", "cost"}));
  ASSERT_EQ(scene["paths"].size(), 1u);
  EXPECT_EQ(scene["paths"][0]["label"], "estimate");
  EXPECT_EQ(scene["paths"][0]["positions_m"].size(), 11u);
  EXPECT_EQ(scene["plan"], "topdown.png");

  const auto mesh = client.Get("/mesh.bin");
  ASSERT_TRUE(mesh);
  EXPECT_EQ(mesh->status, 200);
  ASSERT_EQ(mesh->body.size(),
            viewer_export::viewer_mesh_bytes(room.vertices.size(), room.triangles.size(), 2));
  EXPECT_EQ(mesh->body.compare(0, 8, std::string("FSVIEW1\0", 8)), 0);
  EXPECT_EQ(u32_at(mesh->body, 8), room.vertices.size());
  EXPECT_EQ(u32_at(mesh->body, 12), room.triangles.size());
  EXPECT_EQ(u32_at(mesh->body, 16), 2u);
  EXPECT_EQ(mesh->body.size(), scene["mesh"]["bytes"].get<size_t>());

  const auto plan = client.Get("/plan.png");
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->status, 200);
  EXPECT_EQ(plan->body.substr(0, 4), "\x89PNG");
}

TEST(ViewServer, NothingElseAndNothingOutsideIsServed) {
  if (!fs::is_directory(app::kThreeJsFolder)) GTEST_SKIP() << "libjs-three is not installed";
  const fs::path dir = scratch_dir("view_server_404");
  write_view_test_folder(dir);
  RunningServer server(app::load_view_content(dir));
  httplib::Client& client = server.client();
  for (const char* path :
       {"/mesh.ply", "/trajectory.tum", "/topdown.png", "/nothing", "/../../etc/passwd",
        "/three/../../../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/three/%2e%2e/three.js",
        "/three/three.js", "/three/build/three.min.js", "/..%2f..%2fetc%2fpasswd"}) {
    const auto response = client.Get(path);
    ASSERT_TRUE(response) << path;
    EXPECT_TRUE(response->status == 404 || response->status == 400)
        << path << ": " << response->status;
    EXPECT_EQ(response->body.find("root:"), std::string::npos) << path;
  }
}

TEST(ViewServer, WithoutAPlanViewPlanIsMissing) {
  if (!fs::is_directory(app::kThreeJsFolder)) GTEST_SKIP() << "libjs-three is not installed";
  const fs::path dir = scratch_dir("view_server_no_plan");
  write_view_test_folder(dir);
  fs::remove(dir / "topdown.png");
  fs::remove(dir / "mesh_error.ply");
  fs::remove(dir / "navmesh.ply");
  const app::ViewContent content = app::load_view_content(dir);
  EXPECT_TRUE(content.scene["plan"].is_null());
  EXPECT_TRUE(content.scene["mesh"]["layers"].empty());
  RunningServer server(content);
  EXPECT_EQ(server.client().Get("/plan.png")->status, 404);
}

TEST(ViewServer, AboveTheBudgetTheMeshIsSimplified) {
  const fs::path dir = scratch_dir("view_server_budget");
  const mesh::TriangleMesh room = write_view_test_folder(dir, 40);  // 19,200 triangles
  app::ViewSettings settings;
  settings.max_triangles = 2000;
  const app::ViewContent content = app::load_view_content(dir, settings);
  const size_t triangles = content.scene["mesh"]["triangles"];
  EXPECT_LE(triangles, 2000u);
  EXPECT_GT(triangles, 200u);
  EXPECT_EQ(content.scene["mesh"]["source_triangles"], room.triangles.size());
  EXPECT_EQ(content.scene["mesh"]["simplified"], true);
  // The layers come along, averaged.
  EXPECT_EQ(content.scene["mesh"]["layers"], nlohmann::json::array({"signed_distance", "cost"}));
  EXPECT_EQ(u32_at(content.mesh_binary, 12), triangles);
  EXPECT_EQ(content.mesh_binary.size(),
            viewer_export::viewer_mesh_bytes(content.scene["mesh"]["vertices"], triangles, 2));
}

TEST(ViewServer, BadFoldersAndAMissingThreeJsAreClear) {
  const fs::path dir = scratch_dir("view_server_bad");
  try {
    app::load_view_content(dir / "missing");
    FAIL() << "no error for a missing folder";
  } catch (const app::ViewError& e) {
    EXPECT_NE(std::string(e.what()).find("no such folder"), std::string::npos) << e.what();
  }
  try {
    app::load_view_content(dir);
    FAIL() << "no error for a folder without a mesh";
  } catch (const app::ViewError& e) {
    EXPECT_NE(std::string(e.what()).find("holds no mesh"), std::string::npos) << e.what();
  }
  write_view_test_folder(dir);
  try {
    app::ViewServer server(app::load_view_content(dir), dir / "no-three");
    FAIL() << "no error for a missing three.js";
  } catch (const app::ViewError& e) {
    EXPECT_NE(std::string(e.what()).find("libjs-three"), std::string::npos) << e.what();
  }
}

TEST(ViewServer, APortInUseIsAnError) {
  if (!fs::is_directory(app::kThreeJsFolder)) GTEST_SKIP() << "libjs-three is not installed";
  const fs::path dir = scratch_dir("view_server_port");
  write_view_test_folder(dir);
  app::ViewServer first(app::load_view_content(dir), app::kThreeJsFolder);
  const int port = first.bind("127.0.0.1", 0);
  app::ViewServer second(app::load_view_content(dir), app::kThreeJsFolder);
  try {
    second.bind("127.0.0.1", port);
    FAIL() << "a second server bound port " << port;
  } catch (const app::ViewError& e) {
    EXPECT_NE(std::string(e.what()).find("in use"), std::string::npos) << e.what();
  }
}

/// A preview refresh with one chunk's mesh (a triangle, or none) and a pose at x.
mapping::MapPreview preview_of(const storage::ChunkKey& key, bool surface, double x) {
  mapping::MapPreview preview;
  mapping::ChunkMesh chunk;
  chunk.key = key;
  if (surface) {
    chunk.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    chunk.mesh.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    chunk.mesh.triangles = {{0, 1, 2}};
  }
  preview.chunks.push_back(chunk);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation().x() = x;
  preview.new_poses.push_back(static_cast<int64_t>(x * 1e9), pose);
  preview.latest_pose = pose;
  preview.has_latest_pose = true;
  preview.frames_read = preview.frames_mapped = static_cast<size_t>(x);
  return preview;
}

/// The chunks of a /live/mesh.bin answer: key -> mesh bytes.
std::map<std::array<int32_t, 3>, size_t> live_chunks(const std::string& body, uint32_t* version) {
  std::map<std::array<int32_t, 3>, size_t> chunks;
  EXPECT_EQ(body.compare(0, 8, std::string(app::kLiveMeshMagic, 8)), 0);
  *version = u32_at(body, 8);
  const uint32_t count = u32_at(body, 12);
  size_t offset = 16;
  for (uint32_t i = 0; i < count; ++i) {
    const std::array<int32_t, 3> key = {static_cast<int32_t>(u32_at(body, offset)),
                                        static_cast<int32_t>(u32_at(body, offset + 4)),
                                        static_cast<int32_t>(u32_at(body, offset + 8))};
    const uint32_t length = u32_at(body, offset + 12);
    chunks[key] = length;
    offset += 16 + length;
  }
  EXPECT_EQ(offset, body.size());
  return chunks;
}

TEST(ViewServer, ALiveRunServesOnlyTheChunksChangedSinceAVersion) {
  if (!fs::is_directory(app::kThreeJsFolder)) GTEST_SKIP() << "libjs-three is not installed";
  auto live = std::make_shared<app::LiveView>("drive");
  RunningServer server(live);
  httplib::Client& client = server.client();
  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_NE(page->body.find("live.js"), std::string::npos);

  live->take(preview_of({0, 0, 0}, true, 1.0));
  live->take(preview_of({1, -2, 0}, true, 2.0));
  live->take(preview_of({0, 0, 0}, false, 3.0));  // its surface carved away

  uint32_t version = 0;
  const auto all = client.Get("/live/mesh.bin?since=0");
  ASSERT_TRUE(all);
  const auto everything = live_chunks(all->body, &version);
  EXPECT_EQ(version, 3u);
  ASSERT_EQ(everything.size(), 2u);
  EXPECT_EQ(everything.at({0, 0, 0}), 0u) << "a chunk without surface comes as an empty one";
  EXPECT_EQ(everything.at({1, -2, 0}), viewer_export::viewer_mesh_bytes(3, 1, 0));

  const auto since_two = client.Get("/live/mesh.bin?since=2");
  ASSERT_TRUE(since_two);
  const auto changed = live_chunks(since_two->body, &version);
  EXPECT_EQ(changed.size(), 1u);
  EXPECT_EQ(changed.count({0, 0, 0}), 1u);
  EXPECT_TRUE(live_chunks(client.Get("/live/mesh.bin?since=3")->body, &version).empty());

  const auto status = client.Get("/live/status.json?path_from=1");
  ASSERT_TRUE(status);
  const nlohmann::json s = nlohmann::json::parse(status->body);
  EXPECT_EQ(s["name"], "drive");
  EXPECT_EQ(s["version"], 3);
  EXPECT_EQ(s["triangles"], 1);
  EXPECT_EQ(s["chunks"], 1) << "the chunk whose surface is gone does not count";
  EXPECT_EQ(s["path_length"], 3);
  ASSERT_EQ(s["path_m"].size(), 2u);
  EXPECT_EQ(s["path_m"][0][0], 2.0);
  EXPECT_EQ(s["pose"]["position_m"][0], 3.0);
  EXPECT_EQ(s["finished"], false);
  live->set_finished();
  EXPECT_EQ(nlohmann::json::parse(client.Get("/live/status.json")->body)["finished"], true);
  // A path_from that is not a count is the whole path.
  EXPECT_EQ(
      nlohmann::json::parse(client.Get("/live/status.json?path_from=x")->body)["path_m"].size(),
      3u);
  // The files of a finished map are not served from a live run.
  EXPECT_EQ(client.Get("/mesh.bin")->status, 404);
}

}  // namespace
}  // namespace featsense::test
