// The pictures of report.html: the PNG files the report names, read from its folder and
// carried inside the page as data URIs.
#include <fstream>
#include <optional>

#include "featsense/viewer_export/base64.hpp"
#include "featsense/viewer_export/html_text.hpp"
#include "internal/html_sections.hpp"

namespace featsense::viewer_export {
namespace {

namespace fs = std::filesystem;

struct Picture {
  const char* title;
  const char* caption;
  const char* file_pointer;  ///< where the report names the file (a JSON pointer)
};

/// The file's bytes, or nothing where it cannot be read.
std::optional<std::string> read_bytes(const fs::path& path) {
  // By its size, not istreambuf_iterator (GCC 12 at -O2 warns of a null dereference in it).
  std::error_code error;
  const uintmax_t size = fs::file_size(path, error);
  if (error) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  std::string bytes(static_cast<size_t>(size), '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(size))) return std::nullopt;
  return bytes;
}

}  // namespace

std::string pictures_section(const nlohmann::json& report, const fs::path& folder) {
  const Picture pictures[] = {
      {"Plan view", "The map from above, cut below its ceilings; the paths over it.",
       "/mesh/plan/file"},
      {"Plan view with the localized path",
       "The map around the path from above, cut below its ceilings: red where the sensor was "
       "localized, amber where it went on odometry alone, gaps where it was lost; blue the "
       "truth where one was given.",
       "/localization/plan/file"},
      {"Mesh error",
       "The plan view coloured by each vertex's signed distance to the true surface: blue "
       "behind it, white on it, red in front.",
       "/eval/mesh/error_files/png"},
      {"Trajectory error over time",
       "The estimated poses against the true ones after the alignment the ATE uses; "
       "triangles mark the loops closed.",
       "/eval/traj/error_files/png"}};
  std::string html;
  for (const Picture& picture : pictures) {
    const nlohmann::json::json_pointer pointer(picture.file_pointer);
    if (!report.contains(pointer) || !report.at(pointer).is_string()) continue;
    // Only a file of the report's own folder, whatever the name says.
    const fs::path file = fs::path(report.at(pointer).get<std::string>()).filename();
    const std::optional<std::string> bytes = read_bytes(folder / file);
    if (!bytes) continue;
    html +=
        "<figure>\n<img alt=\"" + html_escape(picture.title) + "\" src=\"data:image/png;base64," +
        base64_encode(*bytes) + "\">\n<figcaption>" +
        html_escape(std::string(picture.title) + " (" + file.string() + "). " + picture.caption) +
        "</figcaption>\n</figure>\n";
  }
  return html.empty() ? html : "<h2>Pictures</h2>\n" + html;
}

}  // namespace featsense::viewer_export
