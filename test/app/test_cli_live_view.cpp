// featsense live --view end to end: a simulated recording replayed slowly to a live run while
// headless Chromium opens the live page twice; the second time the page shows more mesh than
// the first, without a console error, and the run still ends cleanly on Ctrl+C.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "common/json_file.hpp"
#include "common/page_check.hpp"
#include "common/run_command.hpp"
#include "common/spawn_command.hpp"
#include "common/test_data.hpp"
#include "slam/udp_test_util.hpp"

// Last: <resolv.h>, which httplib.h includes, defines a macro `_res` that Eigen's headers use
// as a parameter name.
#include <httplib.h>

namespace featsense::test {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// The URL that `live --view` printed into `log` ("" where none came within 30 s).
std::string printed_url(const fs::path& log, pid_t child) {
  const std::string marker = "map in the browser: ";
  const auto end = Clock::now() + std::chrono::seconds(30);
  while (Clock::now() < end) {
    const std::string text = text_of(log);
    const size_t at = text.find(marker);
    if (at != std::string::npos && text.find('\n', at) != std::string::npos) {
      return text.substr(at + marker.size(), text.find('\n', at) - at - marker.size());
    }
    int status = 0;
    if (waitpid(child, &status, WNOHANG) == child) return "";
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return "";
}

/// The live run's status.json (null where it does not answer).
nlohmann::json live_status(httplib::Client& client) {
  const auto response = client.Get("/live/status.json");
  if (!response || response->status != 200) return nullptr;
  return nlohmann::json::parse(response->body, nullptr, false);
}

/// Waits until the live map holds more than `triangles` triangles (false after `timeout`).
bool wait_for_triangles(httplib::Client& client, size_t triangles, std::chrono::seconds timeout) {
  const auto end = Clock::now() + timeout;
  while (Clock::now() < end) {
    const nlohmann::json status = live_status(client);
    if (status.is_object() && status["triangles"].get<size_t>() > triangles) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

/// The page has drawn a frame with the mesh it holds (drawn: the triangles of the last frame,
/// the sensor's marker included).
constexpr const char* kReady =
    "window.__featsenseLive && window.__featsenseLive.triangles > 0 && "
    "window.__featsenseLive.drawn >= window.__featsenseLive.triangles";
constexpr const char* kReport = "window.__featsenseLive";

TEST(CliLiveView, ThePageShowsTheMapGrowingWhileTheRunGoesOn) {
  if (!fs::is_directory("/usr/share/javascript/three")) GTEST_SKIP() << "no libjs-three";
  const fs::path dir = scratch_dir("cli_live_view");
  // A walk through the lab: each scan sees more of it. 30 scans of an OS1-64, sent at a
  // tenth of their pace (30 s), so that the run is still growing after the first look, even
  // where Chromium takes many seconds to start on a busy machine;
  // without the refinement, which would hold the scans of its stretch (up to 64) back from
  // the map until the stretch is complete.
  const CommandResult simulated = run_featsense(
      "simulate --quiet --scene lab --sensor os1-64 --frames 30 --format ouster-pcap -o " +
      (dir / "sim").string());
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
  const int lidar = free_udp_port();
  const int imu = free_udp_port();
  const pid_t live = spawn_featsense(
      "live --sensor ouster --meta " + (dir / "sim" / "recording.json").string() +
          " --host 127.0.0.1 --lidar-port " + std::to_string(lidar) + " --imu-port " +
          std::to_string(imu) +
          " --no-mesh --set refine.enabled=false --view --view-port 0 --view-refresh 0.5 -o " +
          (dir / "live").string(),
      dir / "live.log");
  const std::string url = printed_url(dir / "live.log", live);
  if (url.empty()) {
    kill(live, SIGKILL);
    wait_exit_code(live);
    FAIL() << text_of(dir / "live.log");
  }
  ASSERT_EQ(url.rfind("http://127.0.0.1:", 0), 0u) << url;
  const pid_t replay =
      spawn_featsense("replay " + (dir / "sim" / "recording.pcap").string() +
                          " --quiet --rate 0.1 --port 7502:" + std::to_string(lidar) +
                          " --port 7503:" + std::to_string(imu),
                      dir / "replay.log");
  httplib::Client client(url.substr(0, url.size() - 1));  // without the trailing '/'

  const bool mapping = wait_for_triangles(client, 0, std::chrono::seconds(60));
  PageCheck first;
  PageCheck second;
  bool grew = false;
  if (mapping) {
    first = run_page_check(url, (dir / "first.png").string(), kReady, 60000, kReport);
    if (!first.skipped && first.result.contains("reported")) {
      const size_t seen = first.result["reported"]["triangles"].get<size_t>();
      grew = wait_for_triangles(client, seen, std::chrono::seconds(60));
      second = run_page_check(url, (dir / "second.png").string(), kReady, 60000, kReport);
    }
  }
  kill(replay, SIGINT);
  wait_exit_code(replay);
  kill(live, SIGINT);
  const int live_exit = wait_exit_code(live);

  ASSERT_TRUE(mapping) << text_of(dir / "live.log");
  if (first.skipped) GTEST_SKIP() << first.output;
  for (const PageCheck* check : {&first, &second}) {
    ASSERT_EQ(check->exit_code, 0) << check->output;
    EXPECT_TRUE(check->result["console_errors"].empty()) << check->output;
  }
  ASSERT_TRUE(grew) << "the map did not grow after the first look";
  const nlohmann::json& before = first.result["reported"];
  const nlohmann::json& after = second.result["reported"];
  EXPECT_GT(after["triangles"].get<size_t>(), before["triangles"].get<size_t>())
      << first.output << "\n"
      << second.output;
  EXPECT_GE(after["drawn"].get<size_t>(), after["triangles"].get<size_t>()) << second.output;
  EXPECT_GT(after["chunks"].get<size_t>(), 0u) << second.output;
  EXPECT_GT(second.result["differing_fraction"].get<double>(), 0.02) << second.output;

  // Ctrl+C ends the run as without the page: its outputs written.
  EXPECT_EQ(live_exit, 0) << text_of(dir / "live.log");
  const nlohmann::json report = read_json(dir / "live" / "report.json");
  EXPECT_GT(report["frames"].get<size_t>(), 0u);
  EXPECT_GT(report["timings"]["preview"]["count"].get<size_t>(), 0u);
}

TEST(CliLiveView, AViewPortInUseIsOneClearError) {
  if (!fs::is_directory("/usr/share/javascript/three")) GTEST_SKIP() << "no libjs-three";
  const fs::path dir = scratch_dir("cli_live_view_port");
  httplib::Server other;
  const int port = other.bind_to_any_port("127.0.0.1");
  ASSERT_GT(port, 0);
  const CommandResult result = run_featsense(
      "live --sensor velodyne --host 127.0.0.1 --lidar-port " + std::to_string(free_udp_port()) +
      " --view --view-port " + std::to_string(port) + " -o " + (dir / "live").string());
  EXPECT_NE(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("in use"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace featsense::test
