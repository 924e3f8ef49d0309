#pragma once
// Writes a command's machine-readable result: to a file, or to stdout for "-".

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace featsense::app {

/// Writes `document` (pretty-printed) to `path`, or to stdout when path is "-".
/// Throws std::runtime_error naming the path when it cannot be written.
void write_json(const nlohmann::json& document, const std::string& path);

/// A benchmark's result: printed to stdout, and written to `json_path` too unless it is
/// absent or "-".
void print_bench_result(const nlohmann::json& result, const std::optional<std::string>& json_path);

}  // namespace featsense::app
