// featsense live and replay, end to end: a recording replayed over the loopback interface to
// a live run gives the map run's poses; a live run ends on silence or Ctrl+C with its outputs
// written; the errors a user meets (no metadata, a port in use) are one clear message each.

#include <gtest/gtest.h>
#include <httplib.h>
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
#include "common/run_command.hpp"
#include "common/spawn_command.hpp"
#include "common/test_data.hpp"
#include "slam/udp_test_util.hpp"

namespace featsense::test {
namespace {

constexpr const char* kOs1Pcap = "ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap";
constexpr const char* kOs1Json = "ouster/OS-1-128_v2.3.0_1024x10.json";

TEST(CliLive, AReplayedRecordingMapsAsTheRecordingDoes) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const auto dir = scratch_dir("cli_live_replay");
  const int lidar = free_udp_port();
  const int imu = free_udp_port();
  const std::filesystem::path log = dir / "live.log";
  const pid_t live = spawn_featsense(
      "live --sensor ouster --meta " + json.string() + " --host 127.0.0.1 --lidar-port " +
          std::to_string(lidar) + " --imu-port " + std::to_string(imu) +
          " --idle-timeout 2 --no-mesh -o " + (dir / "live").string(),
      log);
  ASSERT_TRUE(wait_for_line(log, "listening on udp://127.0.0.1:", live)) << text_of(log);
  const CommandResult replay = run_featsense(
      "replay " + pcap.string() + " --port 7502:" + std::to_string(lidar) +
      " --port 7503:" + std::to_string(imu) + " --json " + (dir / "replay.json").string());
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_EQ(wait_exit_code(live), 0) << text_of(log);
  EXPECT_NE(text_of(log).find("3 scans mapped"), std::string::npos) << text_of(log);
  const nlohmann::json sent = read_json(dir / "replay.json");
  EXPECT_EQ(sent["sent"], 222);
  EXPECT_EQ(sent["failed"], 0);

  const CommandResult map =
      run_featsense("map " + pcap.string() + " --no-mesh --quiet -o " + (dir / "map").string());
  ASSERT_EQ(map.exit_code, 0) << map.output;
  EXPECT_EQ(text_of(dir / "live" / "trajectory.tum"), text_of(dir / "map" / "trajectory.tum"));
  const nlohmann::json report = read_json(dir / "live" / "report.json");
  EXPECT_EQ(report["input"]["format"], "ouster-live");
  EXPECT_EQ(report["input"]["path"],
            "udp://127.0.0.1:" + std::to_string(lidar) + "," + std::to_string(imu));
  EXPECT_EQ(report["frames"], 3);
}

TEST(CliLive, CtrlCWhileMappingWritesTheMapAndExitsCleanly) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const auto dir = scratch_dir("cli_live_ctrl_c_mapping");
  const int lidar = free_udp_port();
  const int imu = free_udp_port();
  const pid_t live = spawn_featsense(
      "live --sensor ouster --meta " + json.string() + " --host 127.0.0.1 --lidar-port " +
          std::to_string(lidar) + " --imu-port " + std::to_string(imu) +
          " --no-mesh --set map.flush_interval=1 -o " + (dir / "live").string(),
      dir / "live.log");
  ASSERT_TRUE(wait_for_line(dir / "live.log", "listening on", live)) << text_of(dir / "live.log");
  const CommandResult replay =
      run_featsense("replay " + pcap.string() + " --quiet --port 7502:" + std::to_string(lidar) +
                    " --port 7503:" + std::to_string(imu));
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  // The three scans are mapped and flushed (every second here); the sensor then falls silent.
  const bool flushed = wait_for_first_flush(dir / "live" / "map.h5.journal", live);
  kill(live, SIGINT);
  const int live_exit = wait_exit_code(live);
  ASSERT_TRUE(flushed) << text_of(dir / "live.log");
  // Ctrl+C is how a live run ends: exit 0, the map, the poses and the report written.
  EXPECT_EQ(live_exit, 0) << text_of(dir / "live.log");
  EXPECT_NE(text_of(dir / "live.log").find("stopped: the map"), std::string::npos)
      << text_of(dir / "live.log");
  const nlohmann::json report = read_json(dir / "live" / "report.json");
  EXPECT_EQ(report["frames"], 3);
  EXPECT_TRUE(std::filesystem::exists(dir / "live" / "trajectory.tum"));
  EXPECT_TRUE(std::filesystem::exists(dir / "live" / "map.h5"));
}

TEST(CliLive, CtrlCEndsAWaitWithOneClearMessage) {
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const auto dir = scratch_dir("cli_live_ctrl_c");
  const std::filesystem::path log = dir / "live.log";
  const pid_t live = spawn_featsense(
      "live --sensor ouster --meta " + json.string() + " --host 127.0.0.1 --lidar-port " +
          std::to_string(free_udp_port()) + " --imu-port " + std::to_string(free_udp_port()) +
          " -o " + (dir / "live").string(),
      log);
  ASSERT_TRUE(wait_for_line(log, "listening on", live)) << text_of(log);
  kill(live, SIGINT);
  // Nothing was sent: no scan, said so, not a hang.
  EXPECT_NE(wait_exit_code(live), 0);
  EXPECT_NE(text_of(log).find("no scan came before the stop"), std::string::npos) << text_of(log);
}

/// A stub of an Ouster sensor's HTTP API on a free port of 127.0.0.1, answering
/// /api/v1/sensor/metadata with `status` and `body`.
class SensorApiStub {
 public:
  SensorApiStub(int status, std::string body) {
    server_.Get("/api/v1/sensor/metadata",
                [status, body](const httplib::Request&, httplib::Response& response) {
                  response.status = status;
                  response.set_content(body, "application/json");
                });
    port_ = server_.bind_to_any_port("127.0.0.1");
    // Bound already: a client that connects before listen() starts waits in the backlog.
    thread_ = std::thread([this] { server_.listen_after_bind(); });
  }
  ~SensorApiStub() {
    server_.stop();
    thread_.join();
  }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }

 private:
  httplib::Server server_;
  int port_ = 0;
  std::thread thread_;
};

TEST(CliLive, TheMetadataComesFromTheSensorsHttpApiAndIsKept) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const SensorApiStub sensor(200, text_of(json));
  const auto dir = scratch_dir("cli_live_metadata_fetch");
  const int lidar = free_udp_port();
  const std::filesystem::path log = dir / "live.log";
  const pid_t live = spawn_featsense("live --sensor ouster --sensor-address " + sensor.address() +
                                         " --host 127.0.0.1 --lidar-port " + std::to_string(lidar) +
                                         " --imu-port " + std::to_string(free_udp_port()) +
                                         " --idle-timeout 1 --no-mesh --no-loop-closure -o " +
                                         (dir / "live").string(),
                                     log);
  ASSERT_TRUE(wait_for_line(log, "listening on", live)) << text_of(log);
  const CommandResult replay =
      run_featsense("replay " + pcap.string() + " --quiet --port 7502:" + std::to_string(lidar));
  EXPECT_EQ(replay.exit_code, 0) << replay.output;
  EXPECT_EQ(wait_exit_code(live), 0) << text_of(log);
  EXPECT_EQ(text_of(dir / "live" / "sensor_metadata.json"), text_of(json));
  EXPECT_EQ(read_json(dir / "live" / "report.json")["frames"], 3);
}

TEST(CliLive, ASensorApiThatFailsIsOneClearError) {
  const auto dir = scratch_dir("cli_live_metadata_errors");
  const auto live_with = [&](const std::string& address) {
    return run_featsense("live --sensor ouster --sensor-address " + address +
                         " --host 127.0.0.1 --lidar-port " + std::to_string(free_udp_port()) +
                         " -o " + (dir / "out").string());
  };
  {
    const SensorApiStub old_firmware(404, "not found");
    const CommandResult r = live_with(old_firmware.address());
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.output.find("HTTP status 404"), std::string::npos) << r.output;
  }
  {
    const SensorApiStub garbled(200, "<html>");
    const CommandResult r = live_with(garbled.address());
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.output.find("not a JSON object"), std::string::npos) << r.output;
  }
  // Nobody there: a free port on this machine refuses the connection.
  const CommandResult nobody = live_with("127.0.0.1:" + std::to_string(free_udp_port()));
  EXPECT_NE(nobody.exit_code, 0);
  EXPECT_NE(nobody.output.find("no answer"), std::string::npos) << nobody.output;
}

TEST(CliLive, BadSetupsAreOneClearError) {
  const auto dir = scratch_dir("cli_live_errors");
  const CommandResult no_meta =
      run_featsense("live --sensor ouster --host 127.0.0.1 --lidar-port " +
                    std::to_string(free_udp_port()) + " -o " + (dir / "a").string());
  EXPECT_NE(no_meta.exit_code, 0);
  EXPECT_NE(no_meta.output.find("--meta FILE"), std::string::npos) << no_meta.output;

  // A port another program holds.
  const int port = free_udp_port();
  const int holder = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(holder, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
  const CommandResult in_use =
      run_featsense("live --sensor velodyne --host 127.0.0.1 --lidar-port " + std::to_string(port) +
                    " -o " + (dir / "b").string());
  ::close(holder);
  EXPECT_NE(in_use.exit_code, 0);
  EXPECT_NE(in_use.output.find("cannot listen on 127.0.0.1:" + std::to_string(port)),
            std::string::npos)
      << in_use.output;

  const CommandResult bad_sensor = run_featsense("live --sensor hesai -o " + (dir / "c").string());
  EXPECT_NE(bad_sensor.exit_code, 0);
  const CommandResult bad_rate = run_featsense("replay /dev/null --rate 0");
  EXPECT_NE(bad_rate.exit_code, 0);
}

}  // namespace
}  // namespace featsense::test
