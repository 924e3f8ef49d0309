#include "featsense/viewer_export/viewer_page.hpp"

#include <utility>

namespace featsense::viewer_export {
namespace embedded {
// Generated from web/ at configure time (viewer_export/CMakeLists.txt).
std::vector<std::pair<std::string, std::string>> viewer_page();
}  // namespace embedded

namespace {

std::string content_type(const std::string& name) {
  const auto ends_with = [&](const std::string& suffix) {
    return name.size() >= suffix.size() &&
           name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (ends_with(".html")) return "text/html; charset=utf-8";
  if (ends_with(".js")) return "application/javascript; charset=utf-8";
  if (ends_with(".css")) return "text/css; charset=utf-8";
  return "application/octet-stream";
}

}  // namespace

const std::vector<PageFile>& viewer_page_files() {
  static const std::vector<PageFile> files = [] {
    std::vector<PageFile> result;
    for (auto& [name, text] : embedded::viewer_page())
      result.push_back({"/" + name, content_type(name), std::move(text)});
    return result;
  }();
  return files;
}

}  // namespace featsense::viewer_export
