// featsense view end to end: the bad paths (one clear message, a non-zero exit), a server that
// prints its URL and stops on Ctrl+C, and the page in headless Chromium with the mesh drawn; a
// tile set streamed, coarse from afar and at full resolution close up.

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "app/view_test_folder.hpp"
#include "common/page_check.hpp"
#include "common/run_command.hpp"
#include "common/test_data.hpp"
#include "featsense/viewer_export/tile_set.hpp"
#include "mesh/map_tile_scene.hpp"

// Last: <resolv.h>, which httplib.h includes, defines a macro `_res` that Eigen's headers use
// as a parameter name.
#include <httplib.h>

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

/// The lines of `output` that report an error.
size_t error_lines(const std::string& output) {
  size_t count = 0;
  for (size_t at = output.find("error"); at != std::string::npos; at = output.find("error", at + 1))
    ++count;
  return count;
}

void expect_one_clear_error(const CommandResult& result, const std::string& words) {
  EXPECT_NE(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find(words), std::string::npos) << result.output;
  EXPECT_EQ(error_lines(result.output), 1u) << result.output;
  EXPECT_EQ(std::count(result.output.begin(), result.output.end(), '\n'), 1) << result.output;
}

/// `featsense view ARGS` running in the background; Ctrl+C (SIGINT) at the end.
class ViewProcess {
 public:
  explicit ViewProcess(const std::string& args) {
    int pipe_fds[2];
    if (pipe(pipe_fds) != 0) return;
    pid_ = fork();
    if (pid_ == 0) {
      dup2(pipe_fds[1], STDOUT_FILENO);
      close(pipe_fds[0]);
      close(pipe_fds[1]);
      execl("/bin/sh", "sh", "-c", ("exec " + featsense_program() + " view " + args).c_str(),
            static_cast<char*>(nullptr));
      _exit(127);
    }
    close(pipe_fds[1]);
    output_ = fdopen(pipe_fds[0], "r");
  }
  ~ViewProcess() {
    if (pid_ > 0 && exit_code_ < 0) stop();
    if (output_ != nullptr) fclose(output_);
  }
  /// The first line the program printed (its URL, with --quiet).
  std::string first_line() {
    char line[512] = {};
    if (output_ == nullptr || fgets(line, sizeof(line), output_) == nullptr) return "";
    std::string text(line);
    if (!text.empty() && text.back() == '\n') text.pop_back();
    return text;
  }
  /// Sends SIGINT and returns the exit code.
  int stop() {
    kill(pid_, SIGINT);
    int status = 0;
    waitpid(pid_, &status, 0);
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return exit_code_;
  }

 private:
  pid_t pid_ = -1;
  FILE* output_ = nullptr;
  int exit_code_ = -1;
};

TEST(CliView, AMissingFolderIsOneClearError) {
  const fs::path dir = scratch_dir("cli_view_missing");
  expect_one_clear_error(run_featsense("view " + (dir / "nowhere").string()), "no such folder");
}

TEST(CliView, AFolderWithoutAMeshIsOneClearError) {
  const fs::path dir = scratch_dir("cli_view_no_mesh");
  std::ofstream(dir / "report.json") << "{}";
  expect_one_clear_error(run_featsense("view " + dir.string()), "holds no mesh");
}

TEST(CliView, AMissingThreeJsIsOneClearError) {
  const fs::path dir = scratch_dir("cli_view_no_three");
  write_view_test_folder(dir);
  expect_one_clear_error(run_featsense("view " + dir.string() + " --three " + (dir / "x").string()),
                         "libjs-three");
}

TEST(CliView, APortInUseIsOneClearError) {
  if (!fs::is_directory("/usr/share/javascript/three")) GTEST_SKIP() << "no libjs-three";
  const fs::path dir = scratch_dir("cli_view_port");
  write_view_test_folder(dir);
  // A listening socket of this test on a free port.
  const int sock = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(sock, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  ASSERT_EQ(bind(sock, reinterpret_cast<sockaddr*>(&address), sizeof(address)), 0);
  ASSERT_EQ(listen(sock, 1), 0);
  socklen_t length = sizeof(address);
  ASSERT_EQ(getsockname(sock, reinterpret_cast<sockaddr*>(&address), &length), 0);
  const int port = ntohs(address.sin_port);
  expect_one_clear_error(run_featsense("view " + dir.string() + " --port " + std::to_string(port)),
                         "in use");
  close(sock);
}

TEST(CliView, PrintsItsUrlServesAndStopsOnCtrlC) {
  if (!fs::is_directory("/usr/share/javascript/three")) GTEST_SKIP() << "no libjs-three";
  const fs::path dir = scratch_dir("cli_view_serve");
  write_view_test_folder(dir);
  ViewProcess view(dir.string() + " --port 0 --quiet");
  const std::string url = view.first_line();
  ASSERT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;
  httplib::Client client(url.substr(0, url.size() - 1));  // without the trailing '/'
  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_EQ(view.stop(), 0);
}

TEST(CliView, ThePageDrawsTheMeshInHeadlessChromium) {
  if (!fs::is_directory("/usr/share/javascript/three")) GTEST_SKIP() << "no libjs-three";
  const fs::path dir = scratch_dir("cli_view_browser");
  write_view_test_folder(dir, 30);
  ViewProcess view(dir.string() + " --port 0 --quiet");
  const std::string url = view.first_line();
  ASSERT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;
  const std::string screenshot = (dir / "view.png").string();
  PageCheck check = run_page_check(
      url, screenshot, "window.__featsenseReady === true && window.__featsenseDrawnTriangles > 0",
      60000);
  if (check.skipped) GTEST_SKIP() << check.output;
  ASSERT_EQ(check.exit_code, 0) << check.output;
  ASSERT_TRUE(check.result.is_object()) << check.output;
  EXPECT_EQ(check.result["loaded"], true) << check.output;
  EXPECT_TRUE(check.result["console_errors"].empty()) << check.output;
  // The room fills about half the view; the panel alone differs in about 12 % of it.
  EXPECT_GT(check.result["differing_fraction"].get<double>(), 0.3) << check.output;
  EXPECT_EQ(view.stop(), 0);
}

/// The npm modules of the tile-set page, where scripts/install-web.sh put them.
bool web_modules_present() {
  return fs::is_directory(fs::path(FEATSENSE_SOURCE_DIR) / "viewer_export" / "web" / "npm" /
                          "node_modules" / "3d-tiles-renderer");
}

/// A tile set of 4 x 4 tiles of 3.2 m with three levels (test/mesh/map_tile_scene.hpp).
fs::path write_test_tile_set(const std::string& name) {
  const fs::path dir = scratch_dir(name);
  storage::MemoryChunkStore store = tile_scene_store();
  viewer_export::TileSetSettings settings;
  settings.tile_size_m = 3.0;
  settings.write_ply = false;
  viewer_export::write_tile_set(store, dir.string(), settings);
  return dir;
}

TEST(CliView, TheOutputOfMapWithTilesShowsItsTileSet) {
  if (!web_modules_present()) GTEST_SKIP() << "no npm modules (scripts/install-web.sh)";
  const fs::path out = scratch_dir("cli_view_map_tiles");
  fs::rename(write_test_tile_set("cli_view_map_tiles_set"), out / "tiles");
  std::ofstream(out / "report.json") << "{}";
  ViewProcess view(out.string() + " --port 0");
  const std::string loaded = view.first_line();
  EXPECT_NE(loaded.find("tile set " + (out / "tiles").string() + " (21 tiles of every level)"),
            std::string::npos)
      << loaded;
  EXPECT_EQ(view.stop(), 0);
}

TEST(CliView, ATileSetWithoutItsModulesIsOneClearError) {
  const fs::path dir = write_test_tile_set("cli_view_tiles_no_modules");
  expect_one_clear_error(
      run_featsense("view " + dir.string() + " --web-modules " + (dir / "x").string()),
      "scripts/install-web.sh");
}

TEST(CliView, ATileSetStreamsCoarseFromAfarAndFullResolutionCloseUp) {
  if (!web_modules_present()) GTEST_SKIP() << "no npm modules (scripts/install-web.sh)";
  const fs::path dir = write_test_tile_set("cli_view_tiles");
  ViewProcess view(dir.string() + " --port 0 --quiet");
  const std::string url = view.first_line();
  ASSERT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;

  // Only the files listed at start are served: nothing by a path of the request's choosing.
  httplib::Client client(url.substr(0, url.size() - 1));
  EXPECT_EQ(client.Get("/tileset/tileset.json")->status, 200);
  EXPECT_EQ(client.Get("/tileset/tiles/0/0_0.glb")->status, 200);
  EXPECT_EQ(client.Get("/tileset/../tileset.json")->status, 404);
  EXPECT_EQ(client.Get("/tileset/tiles.json")->status, 404);
  EXPECT_EQ(client.Get("/modules/three/package.json")->status, 404);
  EXPECT_EQ(client.Get("/modules/three/build/three.module.js")->status, 200);

  // From afar: the whole map from its coarsest level.
  const std::string afar = (dir / "afar.png").string();
  PageCheck check = run_page_check(url, afar, "window.featsenseTiles.firstFrameMs !== null", 60000,
                                   "window.featsenseTiles");
  if (check.skipped) GTEST_SKIP() << check.output;
  ASSERT_EQ(check.exit_code, 0) << check.output;
  EXPECT_TRUE(check.result["console_errors"].empty()) << check.output;
  EXPECT_GT(check.result["differing_fraction"].get<double>(), 0.1) << check.output;
  const nlohmann::json& far = check.result["reported"];
  EXPECT_TRUE(far["errors"].empty()) << check.output;
  EXPECT_EQ(far["fullResolutionShown"], 0) << check.output;

  // Close to the ball (2 m): full-resolution tiles replace the coarse ones there.
  const std::string close = (dir / "close.png").string();
  check = run_page_check(url + "?focus=0.2,-0.1,0.7&distance=2", close,
                         "window.featsenseTiles.fullResolutionShown > 0", 60000,
                         "window.featsenseTiles");
  ASSERT_EQ(check.exit_code, 0) << check.output;
  EXPECT_TRUE(check.result["reported"]["visible"]["0"].size() > 0) << check.output;
  EXPECT_GT(check.result["differing_fraction"].get<double>(), 0.3) << check.output;
  EXPECT_EQ(view.stop(), 0);
}

}  // namespace
}  // namespace featsense::test
