#pragma once
/// The viewer page (`featsense view`): its HTML, JavaScript and CSS, kept as files in
/// viewer_export/web/ and built into the program (cmake/FeatsenseEmbed.cmake), so that the
/// page always matches the server that serves it and nothing needs installing beside the
/// program. three.js is not among them: it comes from Debian's libjs-three at run time (and,
/// for the tile-set page, with 3d-tiles-renderer from npm: scripts/install-web.sh).

#include <string>
#include <vector>

namespace featsense::viewer_export {

struct PageFile {
  std::string path;          ///< the URL path, "/index.html"
  std::string content_type;  ///< "text/html; charset=utf-8"; JavaScript as
                             ///< "application/javascript; charset=utf-8"
  std::string body;
};

/// Every file of the page.
const std::vector<PageFile>& viewer_page_files();

}  // namespace featsense::viewer_export
