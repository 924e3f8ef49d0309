#pragma once
// Writes a command's machine-readable result: to a file, or to stdout for "-".

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace featsense::app {

/// Writes `document` (pretty-printed) to `path`, or to stdout when path is "-".
/// Throws std::runtime_error naming the path when it cannot be written.
void write_json(const nlohmann::json& document, const std::string& path);

/// {"min", "median", "max"} of the values (all 0 when empty).
nlohmann::json min_median_max(const std::vector<double>& values);

}  // namespace featsense::app
