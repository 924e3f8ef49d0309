// featsense localize: a recording found in a saved map and tracked on its surface, within
// centimetres of the truth, from a file and from a sensor on the network (a recording
// replayed); a recording of another place never found (its own exit status); the map the
// same bytes after every run; maps it cannot use refused with one clear message.

#include <gtest/gtest.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "common/file_bytes.hpp"
#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/small_map_options.hpp"
#include "common/spawn_command.hpp"
#include "common/test_data.hpp"
#include "slam/udp_test_util.hpp"

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

class CliLocalize : public ::testing::Test {
 public:
  static void SetUpTestSuite() {
    const fs::path dir = scratch_dir("cli_localize_input");
    dir_ = new fs::path(dir);
    CommandResult run =
        run_featsense("simulate --quiet --scene lab --frames 40 -o " + (dir / "walk").string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    // Another path through the same room: higher, tilted, faster; other noise.
    run = run_featsense("simulate --quiet --scene lab --path drone --seed 3 --frames 30 -o " +
                        (dir / "drone").string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    run = run_featsense("simulate --quiet --scene corridor --frames 20 -o " +
                        (dir / "corridor").string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    // The map's frame is the simulation's: it starts from the true first pose beside it.
    run = run_featsense("map " + (dir / "walk").string() + " -o " + (dir / "map").string() +
                        kSmallMap + " --no-mesh --set loop.keyframe_distance=0.3");
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path input(const char* name) { return *dir_ / name; }
  static fs::path map() { return *dir_ / "map" / "map.h5"; }

 private:
  static fs::path* dir_;
};
fs::path* CliLocalize::dir_ = nullptr;

struct Row {
  std::string status;
  std::vector<double> pose;  ///< x y z qx qy qz qw; empty while lost
};

std::vector<Row> read_status(const fs::path& csv) {
  std::vector<Row> rows;
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);  // the header
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream split(line);
    for (std::string field; std::getline(split, field, ',');) fields.push_back(field);
    Row row;
    row.status = fields.at(1);
    if (!fields.at(2).empty()) {
      for (size_t i = 2; i < 9; ++i) row.pose.push_back(std::stod(fields.at(i)));
    }
    rows.push_back(row);
  }
  return rows;
}

/// x y z qx qy qz qw of each line of a TUM file.
std::vector<std::vector<double>> read_tum_poses(const fs::path& path) {
  std::vector<std::vector<double>> out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t = 0;
    std::vector<double> pose(7);
    fields >> t;
    for (double& v : pose) fields >> v;
    out.push_back(pose);
  }
  return out;
}

double angle_deg(const std::vector<double>& a, const std::vector<double>& b) {
  const double dot = std::abs(a[3] * b[3] + a[4] * b[4] + a[5] * b[5] + a[6] * b[6]);
  return 2.0 * std::acos(std::min(1.0, dot)) * 180.0 / M_PI;
}

TEST_F(CliLocalize, AnotherPathThroughTheMappedRoomIsFoundAndTracked) {
  const fs::path out = scratch_dir("cli_localize_drone");
  const std::string map_before = file_bytes(map());
  const std::string journal_before = file_bytes(map().string() + ".journal");
  const CommandResult run =
      run_featsense("localize " + map().string() + " " + input("drone").string() + " -o " +
                    out.string() + " --gt " + (input("drone") / "gt_trajectory.tum").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("localized at"), std::string::npos) << run.output;

  const nlohmann::json report = read_json(out / "report.json");
  const nlohmann::json& found = report["localization"];
  ASSERT_TRUE(found["localized"].get<bool>()) << found.dump(2);
  EXPECT_LE(found["first_fix"]["seconds_in"].get<double>(), 1.0) << found.dump(2);
  EXPECT_GE(found["localized_share_after_first_fix"].get<double>(), 0.9) << found.dump(2);
  EXPECT_EQ(report["eval"]["localized_over_0_5_m"].get<int>(), 0);

  // Every localized pose near the truth (the map's frame is the simulation's): the map is a
  // coarse one of four seconds of walking (10 cm voxels), the drone climbs and tilts.
  const std::vector<Row> rows = read_status(out / "localization.csv");
  const std::vector<std::vector<double>> truth =
      read_tum_poses(input("drone") / "gt_trajectory.tum");
  ASSERT_EQ(rows.size(), truth.size());
  size_t localized = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].status == "lost") {
      EXPECT_TRUE(rows[i].pose.empty()) << "scan " << i << ": a pose while lost";
      continue;
    }
    if (rows[i].status != "localized") continue;
    ++localized;
    const std::vector<double>& p = rows[i].pose;
    const std::vector<double>& t = truth[i];
    EXPECT_LT(std::hypot(p[0] - t[0], p[1] - t[1], p[2] - t[2]), 0.06) << "scan " << i;
    EXPECT_LT(angle_deg(p, t), 0.6) << "scan " << i;
  }
  EXPECT_GE(localized, 25u);
  // Only scans with a pose go into the trajectory.
  EXPECT_EQ(read_tum_poses(out / "trajectory.tum").size(),
            found["scans"]["localized"].get<size_t>() + found["scans"]["odometry"].get<size_t>());
  EXPECT_TRUE(file_bytes(map()) == map_before) << "the map changed";
  EXPECT_TRUE(file_bytes(map().string() + ".journal") == journal_before) << "its journal changed";

  // The page: the path drawn on the map's plan view, the figures beside it.
  EXPECT_EQ(report["html"], "report.html");
  const std::string page = file_bytes(out / "report.html");
  EXPECT_NE(page.find("featsense localization report"), std::string::npos);
  EXPECT_NE(page.find("Plan view with the localized path"), std::string::npos);
  EXPECT_NE(page.find("Against the truth"), std::string::npos);
  ASSERT_EQ(found["plan"]["file"], "topdown.png") << found["plan"].dump(2);
  EXPECT_EQ(file_bytes(out / "topdown.png").substr(1, 3), "PNG");
}

TEST_F(CliLocalize, ASensorStandingStillIsFoundWithoutMoving) {
  // A robot at its dock at power-on: three seconds at one place of the mapped room (the
  // mapping walk's pose two seconds in), other noise. Standing, it makes no keyframe by
  // moving; it is found from two of its scans a second apart.
  const fs::path dir = scratch_dir("cli_localize_standing");
  const std::vector<std::vector<double>> walk = read_tum_poses(input("walk") / "gt_trajectory.tum");
  ASSERT_GT(walk.size(), 20u);
  {
    std::ofstream tum(dir / "stand.tum");
    tum << std::fixed;
    tum.precision(9);
    for (int i = 0; i < 30; ++i) {
      tum << 1700000000.0 + 0.1 * i;
      for (const double v : walk[19]) tum << ' ' << v;
      tum << '\n';
    }
  }
  CommandResult run =
      run_featsense("simulate --quiet --scene lab --seed 11 --trajectory " +
                    (dir / "stand.tum").string() + " -o " + (dir / "stand").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const fs::path out = dir / "loc";
  run = run_featsense("localize --quiet " + map().string() + " " + (dir / "stand").string() +
                      " -o " + out.string() + " --no-plan --gt " +
                      (dir / "stand" / "gt_trajectory.tum").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json report = read_json(out / "report.json");
  const nlohmann::json& found = report["localization"];
  EXPECT_LE(found["first_fix"]["seconds_in"].get<double>(), 1.5) << found.dump(2);
  EXPECT_EQ(found["localized_share_after_first_fix"].get<double>(), 1.0) << found.dump(2);
  EXPECT_LT(report["eval"]["localized"]["translation_m"]["max"].get<double>(), 0.06);
}

TEST_F(CliLocalize, TheSameRecordingGivesTheSamePosesEveryRun) {
  // The surface around the sensor is gathered in the background as it moves: with a radius
  // of 10 m, anew every 2.5-3.75 m of the drone's 8 m. Which a scan is registered to must
  // not depend on how fast that was.
  std::vector<std::string> runs;
  for (int i = 0; i < 2; ++i) {
    const fs::path out = scratch_dir("cli_localize_repeat_" + std::to_string(i));
    const CommandResult run =
        run_featsense("localize --quiet " + map().string() + " " + input("drone").string() +
                      " -o " + out.string() + " --no-plan --set localize.radius=10");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json report = read_json(out / "report.json");
    EXPECT_GE(report["map_cache"]["targets_built"].get<int>(), 3) << report["map_cache"].dump(2);
    // Every column but the time each scan took.
    std::ifstream csv(out / "localization.csv");
    std::string rows;
    for (std::string line; std::getline(csv, line);) rows += line.substr(0, line.rfind(',')) + "\n";
    runs.push_back(rows);
  }
  EXPECT_GT(runs[0].size(), 1000u);
  EXPECT_EQ(runs[0], runs[1]);
}

TEST_F(CliLocalize, ASensorOnTheNetworkIsFoundAndTracked) {
  const fs::path dir = scratch_dir("cli_localize_live");
  // The drone's flight as the sensor sends it, replayed over the loopback interface.
  CommandResult run = run_featsense(
      "simulate --quiet --scene lab --path drone --seed 3 --frames 20 --format ouster-pcap -o " +
      (dir / "sensor").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const int lidar = free_udp_port();
  const int imu = free_udp_port();
  const fs::path log = dir / "localize.log";
  const pid_t localize = spawn_featsense(
      "localize " + map().string() + " --sensor ouster --meta " +
          (dir / "sensor" / "recording.json").string() + " --host 127.0.0.1 --lidar-port " +
          std::to_string(lidar) + " --imu-port " + std::to_string(imu) +
          " --idle-timeout 2 --no-plan -o " + (dir / "out").string() + " --gt " +
          (dir / "sensor" / "gt_trajectory.tum").string(),
      log);
  ASSERT_TRUE(wait_for_line(log, "listening on udp://127.0.0.1:", localize)) << text_of(log);
  run = run_featsense("replay " + (dir / "sensor" / "recording.pcap").string() +
                      " --quiet --port 7502:" + std::to_string(lidar) +
                      " --port 7503:" + std::to_string(imu));
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(wait_exit_code(localize), 0) << text_of(log);

  const nlohmann::json report = read_json(dir / "out" / "report.json");
  EXPECT_EQ(report["input"]["format"], "ouster-live");
  EXPECT_EQ(report["frames"], 20);
  const nlohmann::json& found = report["localization"];
  ASSERT_TRUE(found["localized"].get<bool>()) << found.dump(2);
  EXPECT_GE(found["scans"]["localized"].get<size_t>(), 15u) << found.dump(2);
  EXPECT_EQ(report["eval"]["localized_over_0_5_m"].get<int>(), 0);
  EXPECT_LT(report["eval"]["localized"]["translation_m"]["max"].get<double>(), 0.06)
      << report["eval"].dump(2);
  // Written as the scans came: one line per scan, a pose for each posed one.
  EXPECT_EQ(read_status(dir / "out" / "localization.csv").size(), 20u);
  EXPECT_EQ(read_tum_poses(dir / "out" / "trajectory.tum").size(),
            found["scans"]["localized"].get<size_t>() + found["scans"]["odometry"].get<size_t>());
}

TEST_F(CliLocalize, CtrlCBeforeTheSensorSentAnythingIsOneClearMessage) {
  const fs::path dir = scratch_dir("cli_localize_live_silent");
  CommandResult run = run_featsense(
      "simulate --quiet --scene lab --frames 1 --format ouster-pcap -o " + (dir / "s").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const fs::path log = dir / "localize.log";
  const pid_t localize = spawn_featsense(
      "localize " + map().string() + " --sensor ouster --meta " +
          (dir / "s" / "recording.json").string() + " --host 127.0.0.1 --lidar-port " +
          std::to_string(free_udp_port()) + " --imu-port " + std::to_string(free_udp_port()) +
          " -o " + (dir / "out").string(),
      log);
  ASSERT_TRUE(wait_for_line(log, "listening on", localize)) << text_of(log);
  kill(localize, SIGINT);
  // Nothing was sent: said so, not "never found in the map", not a hang.
  EXPECT_EQ(wait_exit_code(localize), 1);
  EXPECT_NE(text_of(log).find("no scan came before the stop"), std::string::npos) << text_of(log);
  EXPECT_EQ(text_of(log).find("never found"), std::string::npos) << text_of(log);
}

TEST_F(CliLocalize, ARecordingOrASensorNotBothNorNeither) {
  const fs::path out = scratch_dir("cli_localize_inputs");
  CommandResult run = run_featsense("localize " + map().string() + " " + input("drone").string() +
                                    " --sensor ouster -o " + out.string());
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("excludes"), std::string::npos) << run.output;
  run = run_featsense("localize " + map().string() + " -o " + out.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("nothing to localize"), std::string::npos) << run.output;
  // A range that leaves no scan.
  run = run_featsense("localize " + map().string() + " " + input("drone").string() +
                      " --start 500 -o " + out.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no scan to localize"), std::string::npos) << run.output;
}

TEST_F(CliLocalize, ARecordingOfAnotherPlaceIsNeverFound) {
  const fs::path out = scratch_dir("cli_localize_corridor");
  const std::string map_before = file_bytes(map());
  const CommandResult run = run_featsense("localize " + map().string() + " " +
                                          input("corridor").string() + " -o " + out.string());
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("was never found in"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("No pose was given"), std::string::npos) << run.output;
  const nlohmann::json report = read_json(out / "report.json");
  EXPECT_FALSE(report["localization"]["localized"].get<bool>());
  EXPECT_EQ(report["localization"]["scans"]["lost"].get<size_t>(), 20u);
  EXPECT_TRUE(read_tum_poses(out / "trajectory.tum").empty());
  EXPECT_TRUE(file_bytes(map()) == map_before) << "the map changed";
}

TEST_F(CliLocalize, MapsItCannotUseAreRefusedWithOneClearMessage) {
  const fs::path dir = scratch_dir("cli_localize_bad_maps");
  // Given poses: no keyframes to find the sensor by.
  CommandResult run = run_featsense("map " + input("walk").string() + " --end 5 --gt " +
                                    (input("walk") / "gt_trajectory.tum").string() + " -o " +
                                    (dir / "given").string() + kSmallMap + " --no-mesh");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  run = run_featsense("localize " + (dir / "given" / "map.h5").string() + " " +
                      input("drone").string() + " -o " + (dir / "a").string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("keeps no keyframes"), std::string::npos) << run.output;

  // Another voxel size asked for than the map has.
  run = run_featsense("localize " + map().string() + " " + input("drone").string() + " -o " +
                      (dir / "b").string() + " --set map.voxel_size=0.2");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("map.voxel_size"), std::string::npos) << run.output;

  // A damaged file: the first half of the map.
  const std::string bytes = file_bytes(map());
  const fs::path damaged = dir / "damaged.h5";
  std::ofstream(damaged, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  run = run_featsense("localize " + damaged.string() + " " + input("drone").string() + " -o " +
                      (dir / "c").string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find(damaged.string()), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("Segmentation"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace featsense::test
