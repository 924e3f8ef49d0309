#include "featsense/viewer_export/html_text.hpp"

#include <cmath>
#include <cstdio>

namespace featsense::viewer_export {

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string number_text(double value, int digits) {
  if (!std::isfinite(value)) return "-";
  char text[48];
  // + 0.0: no "-0".
  std::snprintf(text, sizeof(text), "%.*g", digits, value + 0.0);
  return text;
}

}  // namespace featsense::viewer_export
