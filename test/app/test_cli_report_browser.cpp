// report.html of a small demo in headless Chromium (test/tools/page_check.mjs): it loads from a
// file:// address with nothing else to fetch, every picture decodes, no console error, and
// something is drawn. Skips where node, playwright-core or Chromium is missing.

#include <gtest/gtest.h>

#include <filesystem>

#include "common/page_check.hpp"
#include "common/run_command.hpp"
#include "common/test_data.hpp"

namespace featsense::test {
namespace {

namespace fs = std::filesystem;

TEST(CliReportBrowser, DemoReportLoadsOfflineWithEveryPicture) {
  const fs::path out = scratch_dir("cli_report_browser");
  const CommandResult r = run_featsense("demo -o " + out.string() + " --frames 8 --backend cpu");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path page = fs::absolute(out / "report.html");
  ASSERT_TRUE(fs::is_regular_file(page));

  // Ready once every <img> has decoded: a broken data URI never gets a natural width.
  const PageCheck check =
      run_page_check("file://" + page.string(), (out / "report.png").string(),
                     "document.readyState === \"complete\" && document.images.length === 3 && "
                     "Array.from(document.images).every(i => i.complete && i.naturalWidth > 0)",
                     60000);
  if (check.skipped) GTEST_SKIP() << check.output;
  EXPECT_EQ(check.exit_code, 0) << check.output;
  // Exit 0 says it all; the fields say which check failed.
  const nlohmann::json& result = check.result;
  ASSERT_TRUE(result.is_object() && result.contains("loaded") && result.contains("nonblank") &&
              result.contains("console_errors"))
      << check.output;
  EXPECT_EQ(result["loaded"], true) << check.output;
  EXPECT_EQ(result["nonblank"], true) << check.output;
  EXPECT_EQ(result["console_errors"], nlohmann::json::array()) << check.output;
}

}  // namespace
}  // namespace featsense::test
