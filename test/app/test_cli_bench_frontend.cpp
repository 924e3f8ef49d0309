#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/json_file.hpp"
#include "common/run_command.hpp"
#include "common/test_data.hpp"

namespace featsense::test {
namespace {

TEST(CliBenchFrontEnd, FeaturesAreTimedOnEverySimulatedScan) {
  const std::filesystem::path json = scratch_dir("cli_bench_features") / "bench.json";
  const CommandResult result = run_featsense(
      "bench features --scene lab --path walk --scans 3 --quiet --json " + json.string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json figures = read_json(json);
  EXPECT_EQ(figures["benchmark"], "features");
  EXPECT_EQ(figures["sequence_scans"].get<int>(), 3);
  EXPECT_EQ(figures["rows"].get<int>(), 128);
  EXPECT_GT(figures["median_ms"].get<double>(), 0.0);
  EXPECT_LE(figures["median_ms"].get<double>(), figures["max_ms"].get<double>());
  EXPECT_GT(figures["surfaces_per_scan"]["min"].get<double>(), 100.0);
  EXPECT_GT(figures["edges_per_scan"]["min"].get<double>(), 10.0);
  // The fusion only removes edges.
  EXPECT_LE(figures["edges_per_scan"]["max"].get<double>(),
            figures["geometric_edges_per_scan"]["max"].get<double>());
  EXPECT_EQ(figures["intensity_confirmed_scans"].get<int>(), 3);
}

TEST(CliBenchFrontEnd, OdometryTimesEachStageAndScoresTheSimulatedPath) {
  const std::filesystem::path json = scratch_dir("cli_bench_odometry") / "bench.json";
  const CommandResult result = run_featsense(
      "bench odometry --scene lab --path walk --scans 6 --quiet --json " + json.string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json figures = read_json(json);
  EXPECT_EQ(figures["benchmark"], "odometry");
  // The first two scans start the map: timed apart.
  EXPECT_EQ(figures["timed_scans"].get<int>(), 4);
  EXPECT_GT(figures["startup_ms"].get<double>(), 0.0);
  for (const char* stage : {"features", "registration", "total"}) {
    EXPECT_GT(figures[stage]["median_ms"].get<double>(), 0.0) << stage;
  }
  EXPECT_GE(figures["total"]["max_ms"].get<double>(), figures["features"]["max_ms"].get<double>());
  EXPECT_EQ(figures["failed_scans"].get<int>(), 0);
  EXPECT_LT(figures["ape_rmse_m"].get<double>(), 0.05);
}

TEST(CliBenchFrontEnd, ARecordingWithoutFramesIsOneClearError) {
  const std::filesystem::path dir = scratch_dir("cli_bench_odometry_empty");
  std::filesystem::create_directories(dir / "empty");
  const CommandResult result =
      run_featsense("bench odometry --quiet --input " + (dir / "empty").string());
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("empty"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace featsense::test
