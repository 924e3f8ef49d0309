#include "report_html.hpp"

#include <fstream>
#include <stdexcept>

#include "featsense/viewer_export/html_report.hpp"

namespace featsense::app {

void write_report_html(const std::filesystem::path& out, const nlohmann::json& report) {
  const std::filesystem::path file = out / kReportHtml;
  const std::string page = viewer_export::html_report(report, out);
  std::ofstream stream(file, std::ios::binary);
  stream.write(page.data(), static_cast<std::streamsize>(page.size()));
  if (!stream.flush()) throw std::runtime_error("cannot write " + file.string());
}

}  // namespace featsense::app
