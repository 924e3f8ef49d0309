#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/test_data.hpp"

namespace featsense::test {
namespace {

TEST(Cli, VersionAndHelpOnEveryLevel) {
  const CommandResult version = run_featsense("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("featsense "), std::string::npos);
  for (const std::string level :
       {"", "info ", "convert ", "bench tsdf ", "eval traj ", "eval mesh "}) {
    const CommandResult help = run_featsense(level + "--help");
    EXPECT_EQ(help.exit_code, 0) << level;
    EXPECT_NE(help.output.find("--quiet"), std::string::npos) << level << help.output;
  }
}

TEST(Cli, InfoOnTheBuiltInExampleReportsItsShape) {
  const auto dir = scratch_dir("cli_info");
  const CommandResult r = run_featsense("info --quiet --json " + (dir / "info.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("128 x 1024"), std::string::npos) << r.output;
  const nlohmann::json info = read_json(dir / "info.json");
  EXPECT_EQ(info["format"], "builtin-box-room");
  EXPECT_EQ(info["frames"], 10);
  EXPECT_EQ(info["rows"], 128);
  EXPECT_EQ(info["cols"], 1024);
  EXPECT_EQ(info["valid_points"]["min"], 128 * 1024);
  EXPECT_EQ(info["valid_points"]["median"], 128 * 1024);
  EXPECT_NEAR(info["time_span_s"].get<double>(), 0.9, 1e-6);
  EXPECT_EQ(info["times"], "per column, simulated");
}

TEST(Cli, InfoSaysWhereThePointTimesComeFrom) {
  // An HDL-32 scan without a time field, its points in firing order from 270 deg on.
  FEATSENSE_SHARED_FILE(pcd, "velodyne/251370668.pcd");
  const CommandResult derived = run_featsense("info --quiet " + pcd.string());
  ASSERT_EQ(derived.exit_code, 0) << derived.output;
  EXPECT_NE(derived.output.find("times:     from the azimuth (the sweep began 270.1 deg "
                                "clockwise of +x, points in firing order; 0 s where it began)"),
            std::string::npos)
      << derived.output;
  const CommandResult off =
      run_featsense("info --quiet " + pcd.string() + " --set sensor.times_from_azimuth=false");
  ASSERT_EQ(off.exit_code, 0) << off.output;
  EXPECT_NE(off.output.find("times:     none: no time field, and sensor.times_from_azimuth is "
                            "false"),
            std::string::npos)
      << off.output;
}

TEST(Cli, RangeLimitsFromTheConfigDropPoints) {
  // The box room is 20 x 20 x 4 m, the sensor 1.5 m above the floor and 8 m or more from the
  // walls: a 6 m limit keeps only the floor below the steeper beams.
  const CommandResult r = run_featsense("info --quiet --set sensor.max_range=6 --json -");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json info = nlohmann::json::parse(r.output);
  EXPECT_LT(info["valid_points"]["max"].get<double>(), 0.6 * 128 * 1024);
  EXPECT_GT(info["valid_points"]["min"].get<double>(), 0.0);
}

TEST(Cli, ConfigErrorsNameTheKeyAndExitWithTwo) {
  const CommandResult typo = run_featsense("info --set map.voxelsize=0.1");
  EXPECT_EQ(typo.exit_code, 2);
  EXPECT_NE(typo.output.find("did you mean 'map.voxel_size'"), std::string::npos) << typo.output;
  const CommandResult range = run_featsense("info --set map.voxel_size=-1");
  EXPECT_EQ(range.exit_code, 2);
  EXPECT_NE(range.output.find("map.voxel_size"), std::string::npos) << range.output;
  const auto dir = scratch_dir("cli_config");
  std::ofstream(dir / "bad.yaml") << "map:\n  truncation: far\n";
  const CommandResult file = run_featsense("info --config " + (dir / "bad.yaml").string());
  EXPECT_EQ(file.exit_code, 2);
  EXPECT_NE(file.output.find("bad.yaml:2"), std::string::npos) << file.output;
}

TEST(Cli, UnknownSubcommandGetsAHint) {
  const CommandResult r = run_featsense("inof");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("did you mean 'info'"), std::string::npos) << r.output;
}

TEST(Cli, BadInputsGiveOneClearError) {
  const auto dir = scratch_dir("cli_bad_input");
  std::ofstream(dir / "empty.pcd").close();
  std::ofstream(dir / "noise.dat") << "this is not a recording\n";
  for (const auto& [input, expected] : std::vector<std::pair<std::string, std::string>>{
           {(dir / "missing.pcap").string(), "no such file"},
           {(dir / "empty.pcd").string(), "empty file"},
           {(dir / "noise.dat").string(), "unrecognised format"}}) {
    const CommandResult r = run_featsense("info " + input);
    EXPECT_EQ(r.exit_code, 1) << input;
    EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("featsense: error:"), std::string::npos) << r.output;
  }
}

TEST(Cli, ConvertedFramesReadBackAsTheSameRecording) {
  const auto dir = scratch_dir("cli_convert");
  FEATSENSE_SHARED_FILE(pcd, "velodyne/vlp16_1673400472138016708.pcd");
  const CommandResult to_pcd =
      run_featsense("convert --quiet " + pcd.string() + " -o " + (dir / "pcd").string());
  ASSERT_EQ(to_pcd.exit_code, 0) << to_pcd.output;
  const CommandResult original = run_featsense("info --quiet --json - " + pcd.string());
  const CommandResult converted = run_featsense("info --quiet --json - " + (dir / "pcd").string());
  ASSERT_EQ(original.exit_code, 0) << original.output;
  ASSERT_EQ(converted.exit_code, 0) << converted.output;
  const nlohmann::json a = nlohmann::json::parse(original.output);
  const nlohmann::json b = nlohmann::json::parse(converted.output);
  EXPECT_EQ(a["rows"], b["rows"]);
  EXPECT_EQ(a["cols"], b["cols"]);
  EXPECT_EQ(a["valid_points"], b["valid_points"]);
  EXPECT_EQ(a["first_stamp_ns"], b["first_stamp_ns"]);
}

TEST(CliBenchTsdf, IntegratesTheSequenceOncePerPassIntoANewMap) {
  const std::filesystem::path dir = scratch_dir("cli_bench_tsdf");
  const std::filesystem::path json = dir / "bench.json";
  const CommandResult result =
      run_featsense("bench tsdf --backend cpu --map 12x12x6 --scans 3 --passes 2 --quiet --json " +
                    json.string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json figures = read_json(json);
  EXPECT_EQ(figures["backend"], "cpu");
  EXPECT_EQ(figures["passes"].get<int>(), 2);
  EXPECT_EQ(figures["sequence_scans"].get<int>(), 3);
  // The first scan of each pass meets an empty map and is reported on its own.
  EXPECT_EQ(figures["timed_scans"].get<int>(), 4);
  EXPECT_GT(figures["empty_map_ms"].get<double>(), 0.0);
  EXPECT_GT(figures["median_ms"].get<double>(), 0.0);
  EXPECT_LE(figures["median_ms"].get<double>(), figures["max_ms"].get<double>());
  EXPECT_GT(figures["voxels_updated_per_scan"]["median"].get<double>(), 10000.0);
  EXPECT_EQ(figures["map_voxels"][0].get<int>(), 200);  // 12 m / 6.4 cm, odd bricks
}

}  // namespace
}  // namespace featsense::test
