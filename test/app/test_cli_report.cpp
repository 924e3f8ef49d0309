// featsense report OUT: report.html again from a folder's report.json; a folder without one,
// or with a broken one, gets one clear message.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/run_command.hpp"
#include "common/test_data.hpp"

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

TEST(CliReport, WritesThePageFromAReportJson) {
  const fs::path out = scratch_dir("cli_report") / "small";
  fs::create_directories(out);
  std::ofstream(out / "report.json") << R"({"frames": 3, "config": "note: <script>"})";
  const CommandResult r = run_featsense("report " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("report.html"), std::string::npos) << r.output;
  ASSERT_TRUE(fs::is_regular_file(out / "report.html"));
  EXPECT_GT(fs::file_size(out / "report.html"), 500u);
}

TEST(CliReport, AFolderWithoutReportJsonSaysSo) {
  const fs::path out = scratch_dir("cli_report") / "empty";
  fs::create_directories(out);
  const CommandResult r = run_featsense("report " + out.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("no report.json"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "report.html"));

  std::ofstream(out / "report.json") << "{ not json";
  const CommandResult broken = run_featsense("report " + out.string());
  EXPECT_NE(broken.exit_code, 0);
  EXPECT_NE(broken.output.find("not JSON"), std::string::npos) << broken.output;
}

}  // namespace
}  // namespace featsense::test
