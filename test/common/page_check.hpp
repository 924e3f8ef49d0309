#pragma once
// Opens a page in headless Chromium through test/tools/page_check.mjs (playwright-core), for
// the browser tests of report.html and the viewer. Where node, playwright-core or Chromium is
// missing the run says so, and a test skips with that message.

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace featsense::test {

struct PageCheck {
  bool skipped = false;   ///< Chromium, node or playwright-core is not installed
  int exit_code = -1;     ///< 0: loaded, no console errors, not blank
  std::string output;     ///< the script's JSON line (and any error it printed)
  nlohmann::json result;  ///< loaded, load_ms, console_errors, nonblank, differing_fraction
};

inline std::filesystem::path page_check_script() {
  return std::filesystem::path(FEATSENSE_SOURCE_DIR) / "test" / "tools" / "page_check.mjs";
}

/// Loads `url`, waits until `ready_expr` (a JavaScript expression) is true when given, and
/// writes a screenshot to `screenshot`; `report_expr`'s value comes back as result["reported"].
inline PageCheck run_page_check(const std::string& url, const std::string& screenshot,
                                const std::string& ready_expr = "", int timeout_ms = 30000,
                                const std::string& report_expr = "") {
  PageCheck check;
  if (std::system("command -v node >/dev/null 2>&1") != 0) {
    check.skipped = true;
    check.output = "node is not installed";
    return check;
  }
  std::string command = "node '" + page_check_script().string() + "' --url '" + url +
                        "' --screenshot '" + screenshot + "' --timeout-ms " +
                        std::to_string(timeout_ms);
  if (!ready_expr.empty()) command += " --ready-expr '" + ready_expr + "'";
  if (!report_expr.empty()) command += " --report-expr '" + report_expr + "'";
  command += " 2>&1 </dev/null";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return check;
  std::array<char, 4096> buffer{};
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    check.output.append(buffer.data(), n);
  const int status = pclose(pipe);
  check.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  check.skipped = check.exit_code == 77;
  // The JSON is the last line; anything before it is what node printed on its way.
  const size_t last_line = check.output.find_last_of('{');
  const size_t line_start = check.output.rfind('\n', last_line);
  const std::string json_line =
      check.output.substr(line_start == std::string::npos ? 0 : line_start + 1);
  check.result = nlohmann::json::parse(json_line, nullptr, false);
  return check;
}

}  // namespace featsense::test
