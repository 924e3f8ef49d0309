// `featsense simulate` end to end: its folder reads back with `featsense info`, and bad input
// gives one clear error.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "common/file_bytes.hpp"
#include "common/run_command.hpp"
#include "common/test_data.hpp"

namespace featsense::test {
namespace {

/// Lines that hold data: not empty, not a '#' comment.
size_t count_lines(const std::filesystem::path& path) {
  std::ifstream in(path);
  size_t n = 0;
  for (std::string line; std::getline(in, line);) n += line.empty() || line[0] == '#' ? 0 : 1;
  return n;
}

TEST(CliSimulate, LabFramesReadBackWithInfo) {
  const auto dir = scratch_dir("cli_simulate");
  const std::string out = (dir / "lab").string();
  const CommandResult sim = run_featsense("simulate --quiet --scene lab -o " + out + " --frames 3");
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  for (const char* name :
       {"sequence.yaml", "frame_000002.pcd", "gt_trajectory.tum", "gt_mesh.ply", "gt_points.ply"}) {
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "lab" / name)) << name;
  }
  EXPECT_EQ(count_lines(dir / "lab" / "gt_trajectory.tum"), 3u);
  const CommandResult info = run_featsense("info --quiet --json - " + out);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const nlohmann::json j = nlohmann::json::parse(info.output);
  EXPECT_EQ(j["format"], "simulated");
  EXPECT_EQ(j["frames"], 3);
  EXPECT_EQ(j["rows"], 128);  // the os1-128 preset
  EXPECT_EQ(j["cols"], 1024);
  EXPECT_GT(j["valid_points"]["min"].get<int>(), 128 * 1024 / 2);  // a closed room
}

TEST(CliSimulate, SensorFromOusterMetadata) {
  FEATSENSE_SHARED_FILE(meta, "ouster/OS-1-128_v2.3.0_1024x10.json");
  const auto dir = scratch_dir("cli_simulate_meta");
  const std::string out = (dir / "corridor").string();
  const CommandResult sim = run_featsense("simulate --quiet --scene corridor --frames 1 --sensor " +
                                          meta.string() + " -o " + out);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const CommandResult info = run_featsense("info --quiet --json - " + out);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const nlohmann::json j = nlohmann::json::parse(info.output);
  EXPECT_EQ(j["frames"], 1);
  EXPECT_EQ(j["rows"], 128);  // the unit's metadata: OS-1-128, 1024x10
  EXPECT_EQ(j["cols"], 1024);
}

TEST(CliSimulate, OusterPacketsReadBackAsTheFolderOfTheSameRun) {
  const auto dir = scratch_dir("cli_simulate_pcap");
  const std::string pcap_out = (dir / "pcap").string();
  const std::string folder_out = (dir / "folder").string();
  const std::string args = "simulate --quiet --scene lab --frames 3 --rate 20 --seed 4 ";
  const CommandResult pcap = run_featsense(args + "--format ouster-pcap -o " + pcap_out);
  ASSERT_EQ(pcap.exit_code, 0) << pcap.output;
  for (const char* name : {"recording.pcap", "recording.json", "gt_trajectory.tum", "gt_mesh.ply"})
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "pcap" / name)) << name;
  EXPECT_FALSE(std::filesystem::exists(dir / "pcap" / "sequence.yaml"));  // no frame files
  const CommandResult folder = run_featsense(args + "-o " + folder_out);
  ASSERT_EQ(folder.exit_code, 0) << folder.output;
  // The same ground truth, and the pcap reads back as the folder's scans: the same image and
  // the same returns (ranges to the millimetre; test_pcap_recorders.cpp checks each point).
  EXPECT_EQ(file_bytes(dir / "pcap" / "gt_trajectory.tum"),
            file_bytes(dir / "folder" / "gt_trajectory.tum"));
  const CommandResult a = run_featsense("info --quiet --json - " + pcap_out + "/recording.pcap");
  const CommandResult b = run_featsense("info --quiet --json - " + folder_out);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const nlohmann::json ja = nlohmann::json::parse(a.output);
  const nlohmann::json jb = nlohmann::json::parse(b.output);
  EXPECT_EQ(ja["frames"], 3);
  EXPECT_EQ(ja["rows"], jb["rows"]);
  EXPECT_EQ(ja["cols"], jb["cols"]);
  EXPECT_EQ(ja["valid_points"], jb["valid_points"]);
  EXPECT_EQ(ja["warnings"], 0);
  // `map` of the pcap finds the simulation's truth beside it, as it does in a folder: the map
  // starts at the true first pose and is scored against the true surface.
  const CommandResult map = run_featsense("map --quiet --no-loop-closure " + pcap_out +
                                          "/recording.pcap -o " + (dir / "map").string());
  ASSERT_EQ(map.exit_code, 0) << map.output;
  const nlohmann::json report = nlohmann::json::parse(file_bytes(dir / "map" / "report.json"));
  ASSERT_TRUE(report.contains("eval")) << report.dump();
  EXPECT_EQ(report["eval"]["traj"]["ape"]["count"], 3);
  EXPECT_LT(report["eval"]["mesh"]["accuracy"]["median"].get<double>(), 0.05);
  // A rate that Ouster's modes cannot say is one clear error.
  const CommandResult bad = run_featsense(
      "simulate --quiet --scene lab --frames 1 --rate 12.5 --format ouster-pcap -o " + pcap_out);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("whole number"), std::string::npos) << bad.output;
}

TEST(CliSimulate, SameSeedSameFilesOtherSeedOtherNoise) {
  const auto dir = scratch_dir("cli_simulate_seed");
  for (const std::string run : {"a", "b", "c"}) {
    const std::string seed = run == "c" ? "6" : "5";
    const CommandResult r = run_featsense(
        "simulate --quiet --scene parking --path drone --frames 1 "
        "--seed " +
        seed + " -o " + (dir / run).string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const std::string a = file_bytes(dir / "a" / "frame_000000.pcd");
  EXPECT_GT(a.size(), 128u * 1024u * 20u);
  EXPECT_TRUE(a == file_bytes(dir / "b" / "frame_000000.pcd"));
  EXPECT_FALSE(a == file_bytes(dir / "c" / "frame_000000.pcd"));
  EXPECT_TRUE(file_bytes(dir / "a" / "gt_points.ply") == file_bytes(dir / "b" / "gt_points.ply"));
}

void expect_error(const std::string& args, const std::string& fragment) {
  const CommandResult r = run_featsense("simulate --quiet " + args);
  EXPECT_NE(r.exit_code, 0) << args;
  EXPECT_NE(r.output.find("featsense: error:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(fragment), std::string::npos) << r.output;
}

TEST(CliSimulate, BadInputGivesClearErrors) {
  const auto dir = scratch_dir("cli_simulate_bad");
  const std::string out = " -o " + (dir / "out").string();
  expect_error("--scene " + (dir / "missing.ply").string() + out + " --trajectory x.tum",
               "missing.ply: no such mesh file");
  std::ofstream(dir / "empty.ply") << "";
  expect_error("--scene " + (dir / "empty.ply").string() + out + " --trajectory x.tum",
               "empty.ply");
  expect_error("--scene moon" + out, "no such mesh file");
  expect_error("--scene lab --path fly" + out, "unknown path 'fly'");
  std::ofstream(dir / "bad.tum") << "0 0 0 1.5 0 0 0 1\n0.5 1 0 1.5 0 0\n";
  expect_error("--scene lab --trajectory " + (dir / "bad.tum").string() + out, "bad.tum:2:");
  // From the room's centre out through the wall and beyond the scene.
  std::ofstream(dir / "away.tum") << "0 0 0 1.5 0 0 0 1\n2 100 0 1.5 0 0 0 1\n";
  expect_error("--scene lab --trajectory " + (dir / "away.tum").string() + out,
               "the path leaves the scene at t = ");
  expect_error("--scene lab --frames 100000" + out, "room for");
}

TEST(CliSimulate, VelodynePacketsReadBackOneScanPerRevolution) {
  const auto dir = scratch_dir("cli_simulate_velodyne");
  const std::string out = (dir / "vlp32c").string();
  const CommandResult sim = run_featsense(
      "simulate --quiet --scene lab --frames 2 --format velodyne-pcap --sensor vlp32c -o " + out);
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  for (const char* name : {"recording.pcap", "gt_trajectory.tum", "gt_mesh.ply"})
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "vlp32c" / name)) << name;
  EXPECT_FALSE(std::filesystem::exists(dir / "vlp32c" / "sequence.yaml"));  // no frame files
  EXPECT_EQ(count_lines(dir / "vlp32c" / "gt_trajectory.tum"), 2u);
  // The simulated revolutions start at the reader's scan cut, so each is one scan of the
  // reader's grid (the preset's 1900 columns hold the 1808 firings of a turn at 10 Hz);
  // test_pcap_recorders_velodyne.cpp checks each point.
  const CommandResult info = run_featsense("info --quiet --json - " + out + "/recording.pcap");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const nlohmann::json j = nlohmann::json::parse(info.output);
  EXPECT_EQ(j["format"], "velodyne-pcap");
  EXPECT_NE(j["detail"].get<std::string>().find("VLP-32C (product id 0x28)"), std::string::npos);
  EXPECT_EQ(j["frames"], 2);
  EXPECT_EQ(j["rows"], 32);
  EXPECT_EQ(j["cols"], 1900);
  EXPECT_GT(j["valid_points"]["min"].get<int>(), 32 * 1808 / 2);  // a closed room
  EXPECT_EQ(j["warnings"], 0);
  // Only a Velodyne's packets are written so.
  expect_error("--scene lab --frames 1 --format velodyne-pcap --sensor os1-128 -o " + out,
               "'os1-128' is no Velodyne sensor");
}

}  // namespace
}  // namespace featsense::test
