#pragma once
// Text made safe for HTML and SVG: every string of a report goes through here, so that a
// config value or a file name cannot open a tag.

#include <string>
#include <string_view>

namespace featsense::viewer_export {

/// `&`, `<`, `>`, `"` and `'` as character references: safe in text and in quoted attributes.
std::string html_escape(std::string_view text);

/// A number as a report shows it: `%.*g` with `digits` significant digits.
std::string number_text(double value, int digits = 4);

}  // namespace featsense::viewer_export
